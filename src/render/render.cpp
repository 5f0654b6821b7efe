// SPDX-License-Identifier: MIT
#include "trivcon/render.h"

#include <zlib.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <map>
#include <mutex>
#include <ostream>

#include "trivcon/error.h"
#include "trivcon/indices.h"
#include "trivcon/io.h"

// stb_image_write with zlib's deflate (smaller files than stb's own); static so it cannot clash with
// another copy elsewhere.
static unsigned char* trivcon_png_deflate(unsigned char* data, int length, int* out_length, int quality);
#define STBIW_ZLIB_COMPRESS trivcon_png_deflate
#define STB_IMAGE_WRITE_STATIC
#define STB_IMAGE_WRITE_IMPLEMENTATION
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wsign-compare"
#include "stb_image_write.h"
#include "stb_easy_font.h"
#pragma GCC diagnostic pop

static unsigned char* trivcon_png_deflate(unsigned char* data, int length, int* out_length, int quality) {
  (void)quality;
  uLongf size = compressBound(static_cast<uLong>(length));
  auto* out = static_cast<unsigned char*>(STBIW_MALLOC(size));
  if (out == nullptr) return nullptr;
  if (compress2(out, &size, data, static_cast<uLong>(length), 6) != Z_OK) {
    STBIW_FREE(out);
    return nullptr;
  }
  *out_length = static_cast<int>(size);
  return out;
}

namespace trivcon {

namespace {

constexpr double kReferencePixels = 900;  // sizes in RenderOptions and below are for a 900-pixel image side
constexpr double kMargin = 0.04;          // fraction of the image left free on each side
constexpr double kHalfFieldOfView = 12 * kPi / 180;
constexpr double kGlyphLength = 0.4;  // hedgehog spoke length / glyph spacing

using Vector3d = Eigen::Vector3d;

Vector3d vertex(const MatrixX3d& V, int v) { return V.row(v).transpose(); }

Vector3d axis(char name) {
  switch (name) {
    case 'x':
      return Vector3d::UnitX();
    case 'y':
      return Vector3d::UnitY();
    case 'z':
      return Vector3d::UnitZ();
    default:
      throw Error(std::string("render: up axis must be x, y or z, not '") + name + "'");
  }
}

// The picture's "front" axis for each up axis (see render.h).
Vector3d front_axis(char up) { return up == 'z' ? Vector3d(-Vector3d::UnitY()) : Vector3d(Vector3d::UnitZ()); }

std::vector<int> used_vertices(const Topology& t) {
  std::vector<int> used;
  for (int v = 0; v < t.num_vertices; ++v)
    if (t.vertex_component[v] >= 0) used.push_back(v);
  return used;
}

// Centre of the bounding box of the used vertices.
Vector3d bounding_box_centre(const MatrixX3d& V, const std::vector<int>& used) {
  Vector3d lo = Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (int v : used) lo = lo.cwiseMin(vertex(V, v)), hi = hi.cwiseMax(vertex(V, v));
  return used.empty() ? Vector3d::Zero() : Vector3d(0.5 * (lo + hi));
}

// Distance along the viewing direction from the eye to the centre of the mesh.
double centre_depth(const MatrixX3d& V, const Topology& t, const Camera& camera) {
  return (bounding_box_centre(V, used_vertices(t)) - camera.eye).dot(camera.forward);
}

Rgb scaled(const Rgb& c, double intensity) {
  Rgb out;
  for (int k = 0; k < 3; ++k) out[k] = static_cast<std::uint8_t>(std::clamp(c[k] * intensity + 0.5, 0.0, 255.0));
  return out;
}

// The supersampled picture: colour and inverse depth (1/depth, 0 where nothing was drawn) per sample.
struct Canvas {
  Canvas(int pixels_x, int pixels_y, int ss, const Rgb& background)
      : width(pixels_x * ss),
        height(pixels_y * ss),
        ss(ss),
        rgb(3 * static_cast<size_t>(width) * height),
        inverse_depth(static_cast<size_t>(width) * height, 0.0f) {
    for (size_t i = 0; i < inverse_depth.size(); ++i) set(i, background);
  }
  void set(size_t i, const Rgb& c) { std::memcpy(&rgb[3 * i], c.data(), 3); }
  void blend(size_t i, const Rgb& c, double alpha) {
    for (int k = 0; k < 3; ++k) rgb[3 * i + k] = static_cast<std::uint8_t>(std::lround((1 - alpha) * rgb[3 * i + k] + alpha * c[k]));
  }
  size_t index(int x, int y) const { return static_cast<size_t>(y) * width + x; }
  // Calls paint(i, x, y) for the samples whose centres (x, y) = (column + ½, row + ½) lie in [x0, x1] × [y0, y1].
  template <class Paint>
  void for_samples(double x0, double y0, double x1, double y1, const Paint& paint) {
    const int i0 = std::max(0, static_cast<int>(std::ceil(x0 - 0.5))), i1 = std::min(width - 1, static_cast<int>(std::floor(x1 - 0.5)));
    const int j0 = std::max(0, static_cast<int>(std::ceil(y0 - 0.5))), j1 = std::min(height - 1, static_cast<int>(std::floor(y1 - 0.5)));
    for (int j = j0; j <= j1; ++j)
      for (int i = i0; i <= i1; ++i) paint(index(i, j), i + 0.5, j + 0.5);
  }
  // Box-filters each ss × ss block into one pixel.
  Image downsample() const {
    Image image;
    image.width = width / ss;
    image.height = height / ss;
    image.rgb.resize(3 * static_cast<size_t>(image.width) * image.height);
    const int n = ss * ss;
    for (int y = 0; y < image.height; ++y)
      for (int x = 0; x < image.width; ++x)
        for (int k = 0; k < 3; ++k) {
          int sum = 0;
          for (int dy = 0; dy < ss; ++dy)
            for (int dx = 0; dx < ss; ++dx) sum += rgb[3 * index(ss * x + dx, ss * y + dy) + k];
          image.rgb[3 * (static_cast<size_t>(y) * image.width + x) + k] = static_cast<std::uint8_t>((sum + n / 2) / n);
        }
    return image;
  }

  const int width, height, ss;  // in samples; ss samples per pixel along each axis
  std::vector<std::uint8_t> rgb;
  std::vector<float> inverse_depth;
};

// A point projected to sample coordinates, with 1/depth (which is affine in screen space).
struct ScreenPoint {
  double x, y, inverse_depth;
};

class Renderer {
 public:
  Renderer(const MatrixX3d& V, const Topology& t, const Geometry& g, const Field& field, const RenderOptions& o)
      : V_(V),
        t_(t),
        g_(g),
        field_(field),
        o_(o),
        camera_(fit_camera(V, t, o)),
        canvas_(o.width, o.height, o.supersampling, o.palette.background),
        scale_(std::min(o.width, o.height) / kReferencePixels * o.supersampling),
        mean_edge_(mean_edge_length(V, t)) {
    screen_.resize(t.num_vertices);
    for (int v = 0; v < t.num_vertices; ++v) screen_[v] = to_screen(vertex(V, v));
  }

  Image render(const std::vector<std::pair<int, int>>& singularities, const std::vector<Streamline>* streamlines) {
    if (t_.num_faces > 0) {
      draw_surface();
      draw_boundary();
      draw_polygon_edges();
      draw_sharp_edges();
      if (!o_.draw_field) {
      } else if (streamlines != nullptr) {
        for (const Streamline& line : *streamlines) draw_streamline(line);
      } else {
        draw_hedgehog();
      }
      draw_singularities(singularities);
    }
    if (o_.legend) draw_legend(singularities);
    return canvas_.downsample();
  }

 private:
  ScreenPoint to_screen(const Vector3d& p) const {
    const Vector3d s = camera_.project(p);
    return {s.x() * o_.supersampling, s.y() * o_.supersampling, 1 / s.z()};
  }

  // How far toward the viewer lines are moved before the depth test (world units at `depth`): a couple of
  // pixels, plus a little of the edge length for glyphs that leave their (flat) face.
  double depth_offset(double depth, double pixels) const { return pixels * camera_.pixel_size(depth) + 0.1 * mean_edge_; }

  // Light intensity of a unit normal facing the viewer: ambient + Lambert from above-left of the camera.
  double intensity(const Vector3d& n) const {
    const Vector3d light = (-0.35 * camera_.right + 0.5 * camera_.up - camera_.forward).normalized();
    return 0.42 + 0.58 * std::max(0.0, n.dot(light));
  }

  void draw_surface() {
    // Light per vertex, seen from either side, from area-weighted vertex normals (face normals are unit).
    std::vector<Vector3d> vertex_normal(t_.num_vertices, Vector3d::Zero());
    for (int f = 0; f < t_.num_faces; ++f)
      for (int k = 0; k < 3; ++k) vertex_normal[t_.F(f, k)] += g_.face_area(f) * g_.normal.row(f).transpose();
    std::vector<double> light_front(t_.num_vertices), light_back(t_.num_vertices);
    for (int v = 0; v < t_.num_vertices; ++v) {
      const Vector3d n = vertex_normal[v].normalized();
      light_front[v] = intensity(n);
      light_back[v] = intensity(-n);
    }
    for (int f : faces_by_tile()) {
      const Vector3d normal = g_.normal.row(f).transpose();
      const bool front = normal.dot(camera_.eye - vertex(V_, t_.F(f, 0))) > 0;
      double light[3];
      for (int k = 0; k < 3; ++k) {
        const int v = t_.F(f, k);
        const bool smooth = o_.smooth_shading && vertex_normal[v].squaredNorm() > 0;
        light[k] = smooth ? (front ? light_front[v] : light_back[v]) : intensity(front ? normal : Vector3d(-normal));
      }
      fill_triangle(f, light, front ? o_.palette.front : o_.palette.back);
    }
  }

  // Faces ordered by the 32×32-sample tile holding their first corner, so that the z-buffer is visited
  // tile by tile (far fewer cache misses on large meshes); stable, so the order is deterministic.
  std::vector<int> faces_by_tile() const {
    constexpr int kTile = 32;
    const int columns = canvas_.width / kTile + 1, rows = canvas_.height / kTile + 1;
    auto tile_of = [&](int f) {
      const ScreenPoint& p = screen_[t_.F(f, 0)];
      const int x = std::clamp(static_cast<int>(p.x) / kTile, 0, columns - 1), y = std::clamp(static_cast<int>(p.y) / kTile, 0, rows - 1);
      return y * columns + x;
    };
    std::vector<int> start(static_cast<size_t>(columns) * rows + 1, 0), order(t_.num_faces);
    for (int f = 0; f < t_.num_faces; ++f) ++start[tile_of(f) + 1];
    for (size_t k = 1; k < start.size(); ++k) start[k] += start[k - 1];
    for (int f = 0; f < t_.num_faces; ++f) order[start[tile_of(f)]++] = f;
    return order;
  }

  // Z-buffered fill of face f; the light intensity is interpolated from the corners. Barycentric
  // coordinates are affine in the image, so they are stepped along each row.
  void fill_triangle(int f, const double light[3], const Rgb& base) {
    const ScreenPoint& a = screen_[t_.F(f, 0)];
    const ScreenPoint& b = screen_[t_.F(f, 1)];
    const ScreenPoint& c = screen_[t_.F(f, 2)];
    const double area = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
    if (!(std::abs(area) > 1e-12)) return;
    const Eigen::MatrixXd& uv = o_.corner_uv;
    const bool checker = uv.rows() == t_.num_faces && uv.cols() == 6 && base == o_.palette.front;
    // wa(x, y) = ax·x + ay·y + a0, likewise wb; wc = 1 − wa − wb.
    const double ax = (b.y - c.y) / area, ay = (c.x - b.x) / area, a0 = (b.x * c.y - b.y * c.x) / area;
    const double bx = (c.y - a.y) / area, by = (a.x - c.x) / area, b0 = (c.x * a.y - c.y * a.x) / area;
    const int i0 = std::max(0, static_cast<int>(std::ceil(std::min({a.x, b.x, c.x}) - 0.5)));
    const int i1 = std::min(canvas_.width - 1, static_cast<int>(std::floor(std::max({a.x, b.x, c.x}) - 0.5)));
    const int j0 = std::max(0, static_cast<int>(std::ceil(std::min({a.y, b.y, c.y}) - 0.5)));
    const int j1 = std::min(canvas_.height - 1, static_cast<int>(std::floor(std::max({a.y, b.y, c.y}) - 0.5)));
    for (int j = j0; j <= j1; ++j) {
      const double y = j + 0.5;
      for (int i = i0; i <= i1; ++i) {
        const double x = i + 0.5;
        const double wa = ax * x + ay * y + a0, wb = bx * x + by * y + b0, wc = 1 - wa - wb;
        if (wa < 0 || wb < 0 || wc < 0) continue;
        const size_t k = canvas_.index(i, j);
        const float inverse_depth = static_cast<float>(wa * a.inverse_depth + wb * b.inverse_depth + wc * c.inverse_depth);
        if (inverse_depth <= canvas_.inverse_depth[k]) continue;
        canvas_.inverse_depth[k] = inverse_depth;
        Rgb colour = base;
        if (checker) {  // (u, v) interpolated perspective-correctly: weights over depth, normalised
          const double pa = wa * a.inverse_depth, pb = wb * b.inverse_depth, pc = wc * c.inverse_depth, sum = pa + pb + pc;
          const double u = (pa * uv(f, 0) + pb * uv(f, 2) + pc * uv(f, 4)) / sum, v = (pa * uv(f, 1) + pb * uv(f, 3) + pc * uv(f, 5)) / sum;
          if (((static_cast<long long>(std::floor(u)) + static_cast<long long>(std::floor(v))) & 1) != 0) colour = o_.palette.checker;
        }
        canvas_.set(k, scaled(colour, wa * light[0] + wb * light[1] + wc * light[2]));
      }
    }
  }

  // A depth-tested segment with round caps; half-widths w0 at p and w1 at q, in reference pixels.
  void draw_segment(const Vector3d& p, const Vector3d& q, double w0, double w1, const Rgb& colour) {
    const ScreenPoint a = to_screen(p), b = to_screen(q);
    if (!(a.inverse_depth > 0 && b.inverse_depth > 0)) return;  // behind the eye (cannot happen for a fitted view)
    // At least about a pixel wide, so that small pictures still show every line.
    const double r0 = std::max(w0 * scale_, 0.5 * o_.supersampling), r1 = std::max(w1 * scale_, 0.5 * o_.supersampling),
                 r = std::max(r0, r1);
    const double dx = b.x - a.x, dy = b.y - a.y, length2 = dx * dx + dy * dy;
    const double offset_pixels = 1.5 + 2 * std::max(w0, w1);
    canvas_.for_samples(std::min(a.x, b.x) - r, std::min(a.y, b.y) - r, std::max(a.x, b.x) + r, std::max(a.y, b.y) + r,
                        [&](size_t i, double x, double y) {
                          const double s = length2 > 0 ? std::clamp(((x - a.x) * dx + (y - a.y) * dy) / length2, 0.0, 1.0) : 0.0;
                          const double ex = a.x + s * dx - x, ey = a.y + s * dy - y;
                          const double w = r0 + s * (r1 - r0);
                          if (ex * ex + ey * ey > w * w) return;
                          const double depth = 1 / (a.inverse_depth + s * (b.inverse_depth - a.inverse_depth));
                          const double surface = canvas_.inverse_depth[i];
                          if (surface > 0 && depth - depth_offset(depth, offset_pixels) > 1 / surface) return;
                          canvas_.set(i, colour);
                        });
  }

  // The field's colour on face f, faded toward the surface's where the face is seen edge-on, so that lines
  // crowding near silhouettes do not turn them into black bands.
  Rgb field_colour(int f, const Vector3d& at) const {
    const double facing = std::abs(g_.normal.row(f).dot((camera_.eye - at).normalized()));
    const double strength = std::clamp(facing / 0.35, 0.2, 1.0);
    const Rgb faded = scaled(o_.palette.front, 0.6);
    Rgb out;
    for (int k = 0; k < 3; ++k) out[k] = static_cast<std::uint8_t>(std::lround(strength * o_.palette.field[k] + (1 - strength) * faded[k]));
    return out;
  }

  void draw_streamline(const Streamline& line) {
    for (size_t k = 0; k + 1 < line.points.size(); ++k)
      draw_segment(line.points[k], line.points[k + 1], 0.6, 0.6, field_colour(line.faces[k], line.points[k]));
  }

  void draw_boundary() {
    for (const std::vector<int>& loop : t_.boundary_loops)
      for (size_t k = 0; k < loop.size(); ++k)
        draw_segment(vertex(V_, loop[k]), vertex(V_, loop[(k + 1) % loop.size()]), 1.3, 1.3, o_.palette.boundary);
  }

  // Thinner than the boundary; ids outside the mesh are skipped.
  void draw_polygon_edges() {
    for (int e : o_.polygon_edges)
      if (e >= 0 && e < t_.num_edges)
        draw_segment(vertex(V_, t_.edge_vertices(e, 0)), vertex(V_, t_.edge_vertices(e, 1)), 0.8, 0.8, o_.palette.polygon);
  }

  // Drawn like the boundary, in their own colour; ids outside the mesh or of boundary edges are skipped.
  void draw_sharp_edges() {
    for (int e : o_.sharp_edges)
      if (e >= 0 && e < t_.num_edges)
        draw_segment(vertex(V_, t_.edge_vertices(e, 0)), vertex(V_, t_.edge_vertices(e, 1)), 1.3, 1.3, o_.palette.sharp);
  }

  // N tapered spokes from `base` in face f, each `length` long (a single one half as long again: it is
  // alone, and its wedge shape shows the orientation).
  void draw_glyph(int f, const Vector3d& base, double length) {
    const Rgb colour = field_colour(f, base);
    if (field_.N == 1) length *= 1.5;
    for (int k = 0; k < field_.N; ++k) {
      const Vector3d d = g_.direction_in_face(f, field_.angle(f) + 2 * kPi * k / field_.N);
      draw_segment(base, base + length * d, field_.N == 1 ? 1.3 : 0.9, 0.25, colour);
    }
  }

  // Glyphs about `glyph_spacing` pixels apart: one per face where faces are at least that far apart on
  // screen (neighbouring centroids are ≈ 0.58 × the edge length apart), else on an even subset.
  void draw_hedgehog() {
    constexpr double kCentroidSpacing = 0.58;  // distance of neighbouring centroids / edge length, equilateral faces
    const double spacing = o_.glyph_spacing * scale_ / o_.supersampling * camera_.pixel_size(centre_depth(V_, t_, camera_));
    if (kCentroidSpacing * mean_edge_ >= spacing) {
      for (int f = 0; f < t_.num_faces; ++f) {
        if (g_.degenerate_face[f]) continue;
        Vector3d centroid = Vector3d::Zero();
        double perimeter = 0;
        for (int k = 0; k < 3; ++k) {
          centroid += vertex(V_, t_.F(f, k)) / 3;
          perimeter += (vertex(V_, t_.F(f, k)) - vertex(V_, t_.F(f, (k + 1) % 3))).norm();
        }
        draw_glyph(f, centroid, kGlyphLength * kCentroidSpacing * perimeter / 3);
      }
      return;
    }
    for (const SurfacePoint& p : sample_surface(V_, t_, g_, spacing)) draw_glyph(p.face, p.position, kGlyphLength * spacing);
  }

  // Disc radius in reference pixels for index n/N: 9 for ±1, growing as √|index|, within [6, 25].
  double dot_radius(int n) const { return std::clamp(9 * std::sqrt(std::abs(n) / static_cast<double>(field_.N)), 6.0, 25.0); }

  void draw_disc(double cx, double cy, double radius, const Rgb& fill) {
    const double outline = radius + 1.5 * scale_;
    canvas_.for_samples(cx - outline, cy - outline, cx + outline, cy + outline, [&](size_t i, double x, double y) {
      const double d2 = (x - cx) * (x - cx) + (y - cy) * (y - cy);
      if (d2 <= radius * radius)
        canvas_.set(i, fill);
      else if (d2 <= outline * outline)
        canvas_.set(i, o_.palette.text);
    });
  }

  // Whether p is not hidden by the surface: some sample within two of p's image position shows the
  // background or a surface no nearer than p (lenient, so that vertices on the silhouette count as visible).
  bool visible(const ScreenPoint& p) const {
    const int x = static_cast<int>(std::floor(p.x)), y = static_cast<int>(std::floor(p.y));
    if (x < 0 || y < 0 || x >= canvas_.width || y >= canvas_.height) return false;
    const double depth = 1 / p.inverse_depth, limit = depth - depth_offset(depth, 4);
    for (int j = std::max(0, y - 2); j <= std::min(canvas_.height - 1, y + 2); ++j)
      for (int i = std::max(0, x - 2); i <= std::min(canvas_.width - 1, x + 2); ++i) {
        const float surface = canvas_.inverse_depth[canvas_.index(i, j)];
        if (surface == 0 || limit <= 1 / surface) return true;
      }
    return false;
  }

  void draw_singularities(const std::vector<std::pair<int, int>>& singularities) {
    for (auto [v, n] : singularities) {
      if (n == 0 || v < 0 || v >= t_.num_vertices) continue;
      const ScreenPoint p = screen_[v];
      if (!visible(p)) continue;
      draw_disc(p.x, p.y, dot_radius(n) * scale_, n > 0 ? o_.palette.positive : o_.palette.negative);
    }
  }

  // Text at (x, y) (top left, samples) with the font's pixels `unit` samples wide.
  void draw_text(double x, double y, const std::string& text, double unit) {
    std::vector<char> buffer(300 * (text.size() + 1));
    std::string copy = text;
    const int quads = stb_easy_font_print(0, 0, copy.data(), nullptr, buffer.data(), static_cast<int>(buffer.size()));
    for (int q = 0; q < quads; ++q) {
      float corner[2][2];  // vertices 0 and 2 of the quad: opposite corners (x, y, z floats, then colour)
      std::memcpy(corner[0], buffer.data() + 64 * q, 2 * sizeof(float));
      std::memcpy(corner[1], buffer.data() + 64 * q + 32, 2 * sizeof(float));
      canvas_.for_samples(x + unit * corner[0][0], y + unit * corner[0][1], x + unit * corner[1][0], y + unit * corner[1][1],
                          [&](size_t i, double, double) { canvas_.set(i, o_.palette.text); });
    }
  }

  // One legend row: its text and what is drawn left of it.
  struct LegendRow {
    enum Key { None, Disc, Line } key;
    int index;  // for a disc: n (index n/N); for a line: 0 boundary, 1 sharp edges
    std::string text;
  };

  std::vector<LegendRow> legend_rows(const std::vector<std::pair<int, int>>& singularities) const {
    std::map<int, int, std::greater<int>> count;  // index n → vertices, largest first
    for (auto [v, n] : singularities)
      if (n != 0) ++count[n];
    const int N = field_.N;
    std::vector<LegendRow> rows{{LegendRow::None, 0,
                                 "N = " + std::to_string(N) +
                                     (N == 1   ? " (vectors)"
                                      : N == 2 ? " (lines)"
                                      : N == 4 ? " (crosses)"
                                               : "")}};
    for (auto [n, vertices] : count)
      rows.push_back({LegendRow::Disc, n,
                      "index " + std::string(n > 0 ? "+" : "") + format_index(n, N) + ":  " + std::to_string(vertices) +
                          (vertices == 1 ? " vertex" : " vertices")});
    if (count.empty()) rows.push_back({LegendRow::None, 0, "no singular vertices"});
    if (!t_.boundary_loops.empty()) rows.push_back({LegendRow::Line, 0, "boundary"});
    if (!o_.sharp_edges.empty()) rows.push_back({LegendRow::Line, 1, "sharp edges"});
    if (!o_.polygon_edges.empty()) rows.push_back({LegendRow::Line, 2, "polygon edges"});
    return rows;
  }

  // Samples of the box [x0, x1] × [y0, y1] covered by the surface.
  long covered(double x0, double y0, double x1, double y1) {
    long n = 0;
    canvas_.for_samples(x0, y0, x1, y1, [&](size_t i, double, double) { n += canvas_.inverse_depth[i] > 0; });
    return n;
  }

  // The legend goes in the image corner where it hides the least of the surface (lower left on ties).
  void draw_legend(const std::vector<std::pair<int, int>>& singularities) {
    const std::vector<LegendRow> rows = legend_rows(singularities);
    const double unit = 2 * scale_, line = 13 * unit, pad = 12 * scale_, key = 30 * scale_;
    double text_width = 0;
    for (LegendRow row : rows) text_width = std::max(text_width, unit * stb_easy_font_width(row.text.data()));
    const double box_width = key + text_width + 16 * scale_, box_height = line * rows.size() + 10 * scale_;
    double best_x = pad, best_y = canvas_.height - pad - box_height;
    long best = covered(best_x, best_y, best_x + box_width, best_y + box_height);
    for (auto [x, y] : {std::pair{canvas_.width - pad - box_width, canvas_.height - pad - box_height},
                        {pad, pad},
                        {canvas_.width - pad - box_width, pad}}) {
      const long c = covered(x, y, x + box_width, y + box_height);
      if (c < best) best = c, best_x = x, best_y = y;
    }
    canvas_.for_samples(best_x, best_y, best_x + box_width, best_y + box_height,
                        [&](size_t i, double, double) { canvas_.blend(i, o_.palette.background, 0.85); });
    const double x0 = best_x + 8 * scale_;
    for (size_t r = 0; r < rows.size(); ++r) {
      const double y = best_y + 6 * scale_ + line * r, middle = y + 3.5 * unit;
      const double text_x = rows[r].key == LegendRow::None && r == 0 ? x0 : x0 + key;
      if (rows[r].key == LegendRow::Disc)
        draw_disc(x0 + key / 2 - 4 * scale_, middle, std::min(dot_radius(rows[r].index), 12.0) * scale_,
                  rows[r].index > 0 ? o_.palette.positive : o_.palette.negative);
      if (rows[r].key == LegendRow::Line)
        canvas_.for_samples(x0, middle - 1.3 * scale_, x0 + key - 10 * scale_, middle + 1.3 * scale_,
                            [&](size_t i, double, double) {
                              canvas_.set(i, rows[r].index == 1 ? o_.palette.sharp : rows[r].index == 2 ? o_.palette.polygon : o_.palette.boundary);
                            });
      draw_text(text_x, y, rows[r].text, unit);
    }
  }

  const MatrixX3d& V_;
  const Topology& t_;
  const Geometry& g_;
  const Field& field_;
  const RenderOptions& o_;
  const Camera camera_;
  Canvas canvas_;
  const double scale_;  // samples per reference pixel
  const double mean_edge_;
  std::vector<ScreenPoint> screen_;  // projected vertices
};

void check_options(const Topology& t, const Field& field, const RenderOptions& o) {
  if (o.width < 1 || o.height < 1 || o.width > 20000 || o.height > 20000)
    throw Error("render: image size " + std::to_string(o.width) + "x" + std::to_string(o.height) + " out of range (1..20000)");
  if (o.supersampling < 1 || o.supersampling > 8) throw Error("render: supersampling must be 1..8");
  if (!(o.glyph_spacing > 0)) throw Error("render: glyph spacing must be positive");
  if (!std::isfinite(o.azimuth) || !std::isfinite(o.elevation)) throw Error("render: the view angles must be finite");
  if (field.N < 1) throw Error("render: field N must be at least 1");
  if (field.angle.size() != t.num_faces)
    throw Error("render: the field has " + std::to_string(field.angle.size()) + " faces, the mesh " + std::to_string(t.num_faces));
  if (o.corner_uv.size() > 0 && (o.corner_uv.rows() != t.num_faces || o.corner_uv.cols() != 6))
    throw Error("render: the (u, v) are not one pair per corner of the mesh's " + std::to_string(t.num_faces) + " faces");
  if (!o.corner_uv.allFinite()) throw Error("render: a (u, v) is not finite");
}

Image render(const MatrixX3d& V, const Topology& t, const Geometry& g, const Field& field,
             const std::vector<std::pair<int, int>>& singularities, const std::vector<Streamline>* streamlines, const RenderOptions& o) {
  check_options(t, field, o);
  axis(o.up);
  return Renderer(V, t, g, field, o).render(singularities, streamlines);
}

}  // namespace

Eigen::Vector3d Camera::project(const Eigen::Vector3d& p) const {
  const Vector3d q = p - eye;
  const double depth = q.dot(forward);
  return {cx + focal * q.dot(right) / depth, cy - focal * q.dot(up) / depth, depth};
}

Camera fit_camera(const MatrixX3d& V, const Topology& t, const RenderOptions& o) {
  const Vector3d world_up = axis(o.up), front = front_axis(o.up), side = world_up.cross(front);
  const double az = o.azimuth * kPi / 180, el = o.elevation * kPi / 180;
  const Vector3d horizontal = std::cos(az) * front + std::sin(az) * side;
  Camera camera;
  camera.forward = -(std::cos(el) * horizontal + std::sin(el) * world_up);
  camera.right = world_up.cross(horizontal);  // horizontal, so never degenerate (even looking straight down)
  camera.up = camera.right.cross(camera.forward);
  camera.cx = o.width / 2.0;
  camera.cy = o.height / 2.0;
  const std::vector<int> used = used_vertices(t);
  if (used.empty()) {
    camera.eye = -camera.forward;
    return camera;
  }
  // Look at the bounding sphere from far enough that it fits the field of view, then frame the projection.
  const Vector3d centre = bounding_box_centre(V, used);
  double radius = 0;
  for (int v : used) radius = std::max(radius, (vertex(V, v) - centre).norm());
  if (!(radius > 0)) radius = 1;
  camera.eye = centre - camera.forward * (radius / std::sin(kHalfFieldOfView));
  double u0 = std::numeric_limits<double>::infinity(), u1 = -u0, v0 = u0, v1 = -u0;
  for (int v : used) {
    const Vector3d q = vertex(V, v) - camera.eye;
    const double depth = q.dot(camera.forward), u = q.dot(camera.right) / depth, w = q.dot(camera.up) / depth;
    u0 = std::min(u0, u), u1 = std::max(u1, u), v0 = std::min(v0, w), v1 = std::max(v1, w);
  }
  const double fit_x = o.width * (1 - 2 * kMargin) / std::max(u1 - u0, 1e-12);
  const double fit_y = o.height * (1 - 2 * kMargin) / std::max(v1 - v0, 1e-12);
  camera.focal = std::min(fit_x, fit_y);
  camera.cx = o.width / 2.0 - camera.focal * (u0 + u1) / 2;
  camera.cy = o.height / 2.0 + camera.focal * (v0 + v1) / 2;
  return camera;
}

StreamlineOptions render_streamline_options(const MatrixX3d& V, const Topology& t, const RenderOptions& o) {
  const Camera camera = fit_camera(V, t, o);
  StreamlineOptions s;
  s.separation = o.glyph_spacing * std::min(o.width, o.height) / kReferencePixels * camera.pixel_size(centre_depth(V, t, camera));
  return s;
}

Image render_field(const MatrixX3d& V, const Topology& t, const Geometry& g, const Field& field,
                   const std::vector<std::pair<int, int>>& singularities, const RenderOptions& o) {
  if (o.style == FieldStyle::Streamlines) {
    check_options(t, field, o);
    const std::vector<Streamline> lines = trace_streamlines(V, t, g, field, singularities, render_streamline_options(V, t, o));
    return render(V, t, g, field, singularities, &lines, o);
  }
  return render(V, t, g, field, singularities, nullptr, o);
}

Image render_field(const MatrixX3d& V, const Topology& t, const Geometry& g, const Field& field,
                   const std::vector<std::pair<int, int>>& singularities, const std::vector<Streamline>& streamlines,
                   const RenderOptions& o) {
  return render(V, t, g, field, singularities, &streamlines, o);
}

Image render_design(const FieldDesigner& designer, const Design& design, const RenderOptions& o) {
  return render_field(designer.V(), designer.topology(), designer.geometry(), design.field, singular_vertices(design.indices.vertex), o);
}

std::vector<std::pair<int, int>> singular_vertices(const std::vector<int>& vertex_indices) {
  std::vector<std::pair<int, int>> out;
  for (size_t v = 0; v < vertex_indices.size(); ++v)
    if (vertex_indices[v] != 0) out.emplace_back(static_cast<int>(v), vertex_indices[v]);
  return out;
}

void write_png(const std::string& path, const Image& image) {
  if (image.width < 1 || image.height < 1 || image.rgb.size() != 3 * static_cast<size_t>(image.width) * image.height)
    throw Error("cannot write '" + path + "': the image is empty or malformed");
  // Encodes with stb's per-row filter choice and with no filtering, and keeps the smaller: flat shading
  // with thin lines often compresses better unfiltered. stb's filter setting is global: one encoder at a time.
  static std::mutex encoder;
  std::string best;
  for (int filter : {-1, 0}) {
    std::string png;
    auto append = [](void* context, void* data, int size) {
      static_cast<std::string*>(context)->append(static_cast<const char*>(data), size);
    };
    std::lock_guard<std::mutex> lock(encoder);
    stbi_write_force_png_filter = filter;
    if (!stbi_write_png_to_func(append, &png, image.width, image.height, 3, image.rgb.data(), 3 * image.width))
      throw Error("cannot write '" + path + "': PNG encoding failed");
    if (best.empty() || png.size() < best.size()) best.swap(png);
  }
  write_file_atomically(path, [&](std::ostream& out) { out.write(best.data(), static_cast<std::streamsize>(best.size())); });
}

std::vector<int> polygon_edges(const Topology& t, const std::vector<int>& polygon_of_triangle) {
  std::vector<int> out;
  for (int e = 0; e < t.num_edges; ++e) {
    const int L = t.edge_faces(e, 0), R = t.edge_faces(e, 1);
    if (L < 0 || R < 0 || polygon_of_triangle.empty() || polygon_of_triangle[L] != polygon_of_triangle[R]) out.push_back(e);
  }
  return out;
}

}  // namespace trivcon
