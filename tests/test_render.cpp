// SPDX-License-Identifier: MIT
// Tests of trivcon/render.h and trivcon/streamlines.h, and of `trivcon render`, on generated meshes with
// fields designed by trivcon::FieldDesigner. Geometric checks (points on faces, tangency, adjacency) are
// recomputed here from V and F.
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "support.h"
#include "trivcon/design.h"
#include "trivcon/error.h"
#include "trivcon/field_io.h"
#include "trivcon/generate.h"
#include "trivcon/render.h"
#include "trivcon/streamlines.h"

namespace trivcon {
namespace {

using Eigen::Vector3d;
using test::slurp;

// A mesh with a designed field.
struct Scene {
  Mesh mesh;
  std::unique_ptr<FieldDesigner> designer;
  Design design;
  IndexPrescription prescription;
  std::vector<std::pair<int, int>> singularities() const { return {prescription.vertex.begin(), prescription.vertex.end()}; }
  const Topology& t() const { return designer->topology(); }
  const Geometry& g() const { return designer->geometry(); }
};

Scene make_scene(Mesh mesh, const IndexPrescription& p) {
  Scene s;
  s.mesh = std::move(mesh);
  s.prescription = p;
  s.designer = std::make_unique<FieldDesigner>(s.mesh.V, s.mesh.F);
  s.design = s.designer->design(p);
  return s;
}

// The vertex of `m` whose position is largest along `direction`.
int extreme_vertex(const Mesh& m, const Vector3d& direction) {
  int best = 0;
  for (int v = 1; v < m.V.rows(); ++v)
    if (m.V.row(v).dot(direction) > m.V.row(best).dot(direction)) best = v;
  return best;
}

// Unit sphere, N = 1, +1 at the vertex nearest the default camera and at its antipode.
Scene sphere_scene(int level = 3) {
  Mesh m = make_icosphere(level);
  RenderOptions o;
  Topology t = build_topology(m.F, static_cast<int>(m.V.rows()));
  const Vector3d toward_eye = -fit_camera(m.V, t, o).forward;
  IndexPrescription p;
  p.N = 1;
  p.vertex[extreme_vertex(m, toward_eye)] = 1;
  p.vertex[extreme_vertex(m, -toward_eye)] = 1;
  return make_scene(std::move(m), p);
}

// Cube-like sphere, N = 4, +1/4 at the 8 corners (the only valence-3 vertices).
Scene cube_scene(int n = 6) {
  Mesh m = make_cube_sphere(n, true);
  std::vector<int> valence(m.V.rows(), 0);
  for (int f = 0; f < m.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) ++valence[m.F(f, k)];
  IndexPrescription p;
  p.N = 4;
  for (int v = 0; v < m.V.rows(); ++v)
    if (valence[v] == 3) p.vertex[v] = 1;
  EXPECT_EQ(p.vertex.size(), 8u);
  return make_scene(std::move(m), p);
}

Scene torus_scene() {
  IndexPrescription p;
  p.N = 2;
  return make_scene(make_torus(40, 16), p);
}

Scene disk_scene() {
  IndexPrescription p;
  p.N = 1;
  return make_scene(make_disk(8, 6), p);
}

int colour_distance(const Rgb& a, const Rgb& b) {
  int d = 0;
  for (int k = 0; k < 3; ++k) d = std::max(d, std::abs(int(a[k]) - int(b[k])));
  return d;
}

// Fraction of pixels within `tolerance` (per channel) of `colour`.
double fraction_near(const Image& image, const Rgb& colour, int tolerance) {
  long hits = 0;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) hits += colour_distance(image.pixel(x, y), colour) <= tolerance;
  return static_cast<double>(hits) / (static_cast<double>(image.width) * image.height);
}

// Whether some pixel within `radius` of (x, y) has `colour` (within tolerance).
bool colour_near(const Image& image, const Vector3d& at, int radius, const Rgb& colour, int tolerance = 20) {
  const int x0 = static_cast<int>(std::floor(at.x())), y0 = static_cast<int>(std::floor(at.y()));
  for (int y = std::max(0, y0 - radius); y <= std::min(image.height - 1, y0 + radius); ++y)
    for (int x = std::max(0, x0 - radius); x <= std::min(image.width - 1, x0 + radius); ++x)
      if (colour_distance(image.pixel(x, y), colour) <= tolerance) return true;
  return false;
}

RenderOptions small_options() {
  RenderOptions o;
  o.width = 400;
  o.height = 300;
  return o;
}

TEST(Render, IsDeterministic) {
  const Scene s = sphere_scene();
  for (FieldStyle style : {FieldStyle::Hedgehog, FieldStyle::Streamlines}) {
    RenderOptions o = small_options();
    o.style = style;
    const Image a = render_field(s.mesh.V, s.t(), s.g(), s.design.field, s.singularities(), o);
    const Image b = render_field(s.mesh.V, s.t(), s.g(), s.design.field, s.singularities(), o);
    ASSERT_EQ(a.width, 400);
    ASSERT_EQ(a.height, 300);
    ASSERT_EQ(a.rgb.size(), 400u * 300u * 3u);
    EXPECT_TRUE(a.rgb == b.rgb);
    const std::string dir = test::temp_dir("render_deterministic");
    write_png(dir + "/a.png", a);
    write_png(dir + "/b.png", b);
    EXPECT_EQ(slurp(dir + "/a.png"), slurp(dir + "/b.png"));
  }
}

// Options with a field colour found nowhere else in the picture.
RenderOptions magenta_field_options() {
  RenderOptions o = small_options();
  o.palette.field = {255, 0, 255};
  return o;
}

TEST(Render, SurfaceAndFieldAreVisible) {
  const Scene s = sphere_scene();
  for (FieldStyle style : {FieldStyle::Hedgehog, FieldStyle::Streamlines}) {
    RenderOptions o = magenta_field_options();
    o.style = style;
    const Image image = render_field(s.mesh.V, s.t(), s.g(), s.design.field, s.singularities(), o);
    const double background = fraction_near(image, o.palette.background, 0);
    EXPECT_GT(1 - background, 0.2);
    EXPECT_LT(1 - background, 0.9);
    EXPECT_GT(fraction_near(image, o.palette.field, 100), 0.01) << "field lines missing";
    EXPECT_EQ(fraction_near(image, o.palette.back, 30), 0) << "a closed outward mesh shows no back faces";
  }
}

TEST(Render, DenseMeshDrawsASubsetOfGlyphs) {
  // Level 6: 81920 faces, far smaller than the glyph spacing at 400×300, so glyphs go on a subset.
  const Scene s = sphere_scene(6);
  const RenderOptions o = magenta_field_options();
  const Image image = render_field(s.mesh.V, s.t(), s.g(), s.design.field, s.singularities(), o);
  const double field = fraction_near(image, o.palette.field, 100);
  EXPECT_GT(field, 0.01);
  EXPECT_LT(field, 0.15) << "glyphs should stay sparse enough to read";
}

TEST(Render, SingularityDotsAtProjectedVertices) {
  // +1 at the vertex facing the camera (visible) and at its antipode (hidden); then a sphere with
  // three +1 and one −1 all on the visible side.
  const Scene s = sphere_scene();
  const RenderOptions o = small_options();
  const Image image = render_field(s.mesh.V, s.t(), s.g(), s.design.field, s.singularities(), o);
  const Camera camera = fit_camera(s.mesh.V, s.t(), o);
  auto [front, back] = std::make_pair(s.prescription.vertex.begin()->first, s.prescription.vertex.rbegin()->first);
  if (camera.project(s.mesh.V.row(front).transpose()).z() > camera.project(s.mesh.V.row(back).transpose()).z()) std::swap(front, back);
  EXPECT_TRUE(colour_near(image, camera.project(s.mesh.V.row(front).transpose()), 1, o.palette.positive));
  EXPECT_FALSE(colour_near(image, camera.project(s.mesh.V.row(back).transpose()), 3, o.palette.positive));

  Mesh m = make_icosphere(3);
  const Vector3d toward_eye = -camera.forward, side = camera.right, up = camera.up;
  IndexPrescription p;
  p.N = 1;
  const int a = extreme_vertex(m, toward_eye + 0.5 * side), b = extreme_vertex(m, toward_eye - 0.5 * side);
  const int c = extreme_vertex(m, toward_eye + 0.5 * up), d = extreme_vertex(m, toward_eye - 0.5 * up);
  p.vertex[a] = 1, p.vertex[b] = 1, p.vertex[c] = 1, p.vertex[d] = -1;
  const Scene mixed = make_scene(std::move(m), p);
  const Image picture = render_field(mixed.mesh.V, mixed.t(), mixed.g(), mixed.design.field, mixed.singularities(), o);
  for (int v : {a, b, c}) EXPECT_TRUE(colour_near(picture, camera.project(mixed.mesh.V.row(v).transpose()), 1, o.palette.positive)) << v;
  EXPECT_TRUE(colour_near(picture, camera.project(mixed.mesh.V.row(d).transpose()), 1, o.palette.negative));
  // The design's own indices give the same dots.
  const Image from_design = render_design(*mixed.designer, mixed.design, o);
  EXPECT_TRUE(from_design.rgb == picture.rgb);
}

TEST(Render, BackFacesHaveTheirOwnColour) {
  const Scene s = disk_scene();  // flat, normals +z
  RenderOptions o = small_options();
  o.up = 'z';
  o.elevation = -70;  // from below
  const Image below = render_field(s.mesh.V, s.t(), s.g(), s.design.field, {}, o);
  o.elevation = 70;
  const Image above = render_field(s.mesh.V, s.t(), s.g(), s.design.field, {}, o);
  auto warm = [](const Image& image) {
    long n = 0;
    for (int y = 0; y < image.height; ++y)
      for (int x = 0; x < image.width; ++x) {
        const Rgb c = image.pixel(x, y);
        n += c[0] > c[2] + 40;
      }
    return static_cast<double>(n) / (image.width * image.height);
  };
  EXPECT_GT(warm(below), 0.2);
  EXPECT_EQ(warm(above), 0);
  EXPECT_GT(fraction_near(above, o.palette.boundary, 30), 0.001) << "boundary loop outlined";
}

TEST(Render, CameraFramesTheMesh) {
  const Scene s = cube_scene();
  for (auto [az, el] : {std::pair{30.0, 20.0}, {0.0, 0.0}, {200.0, -60.0}, {90.0, 90.0}}) {
    RenderOptions o = small_options();
    o.azimuth = az, o.elevation = el;
    const Camera c = fit_camera(s.mesh.V, s.t(), o);
    double x0 = 1e9, x1 = -1e9, y0 = 1e9, y1 = -1e9;
    for (int v = 0; v < s.mesh.V.rows(); ++v) {
      const Vector3d p = c.project(s.mesh.V.row(v).transpose());
      EXPECT_GT(p.z(), 0);
      x0 = std::min(x0, p.x()), x1 = std::max(x1, p.x()), y0 = std::min(y0, p.y()), y1 = std::max(y1, p.y());
    }
    EXPECT_GE(x0, 0);
    EXPECT_LE(x1, o.width);
    EXPECT_GE(y0, 0);
    EXPECT_LE(y1, o.height);
    EXPECT_TRUE(std::abs(x1 - x0 - 0.92 * o.width) < 1e-6 || std::abs(y1 - y0 - 0.92 * o.height) < 1e-6) << "fills the frame";
  }
}

TEST(Render, RejectsBadOptions) {
  const Scene s = disk_scene();
  RenderOptions o = small_options();
  o.width = 0;
  EXPECT_THROW(render_field(s.mesh.V, s.t(), s.g(), s.design.field, {}, o), Error);
  o = small_options();
  o.up = 'w';
  EXPECT_THROW(render_field(s.mesh.V, s.t(), s.g(), s.design.field, {}, o), Error);
  Field wrong = s.design.field;
  wrong.angle.resize(3);
  EXPECT_THROW(render_field(s.mesh.V, s.t(), s.g(), wrong, {}, small_options()), Error);
  const std::string dir = test::temp_dir("render_bad_png");
  try {
    write_png(dir + "/missing/dir/x.png", render_field(s.mesh.V, s.t(), s.g(), s.design.field, {}, small_options()));
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(dir + "/missing/dir/x.png"), std::string::npos) << e.what();
  }
}

// Barycentric coordinates of p in face f and its distance to the face's plane.
std::pair<Vector3d, double> barycentric(const Scene& s, int f, const Vector3d& p) {
  const Vector3d a = s.mesh.V.row(s.t().F(f, 0)), b = s.mesh.V.row(s.t().F(f, 1)), c = s.mesh.V.row(s.t().F(f, 2));
  const Vector3d n = (b - a).cross(c - a);
  const double area2 = n.squaredNorm();
  const double lb = (p - a).cross(c - a).dot(n) / area2, lc = (b - a).cross(p - a).dot(n) / area2;
  return {Vector3d(1 - lb - lc, lb, lc), std::abs((p - a).dot(n.normalized()))};
}

bool faces_adjacent(const Topology& t, int f, int h) {
  if (f == h) return true;
  for (int k = 0; k < 3; ++k) {
    const int e = t.face_edges(f, k);
    if (t.edge_faces(e, 0) == h || t.edge_faces(e, 1) == h) return true;
  }
  return false;
}

double distance_to_segment(const Vector3d& p, const Vector3d& a, const Vector3d& b) {
  const Vector3d d = b - a;
  const double s = d.squaredNorm() > 0 ? std::clamp((p - a).dot(d) / d.squaredNorm(), 0.0, 1.0) : 0.0;
  return (a + s * d - p).norm();
}

// Every property a streamline must have (see trivcon/streamlines.h).
void check_streamlines(const Scene& s, const std::vector<Streamline>& lines) {
  ASSERT_FALSE(lines.empty());
  const double scale = 2;  // the generated meshes fit in [-2, 2]^3
  const Field& field = s.design.field;
  std::set<int> singular_faces;
  for (auto [v, n] : s.prescription.vertex)
    for (int a = s.t().vertex_face_offsets[v]; a < s.t().vertex_face_offsets[v + 1]; ++a) singular_faces.insert(s.t().vertex_faces[a]);
  double worst_angle = 0, worst_bary = 0, worst_plane = 0, nearest_singularity = 1e9;
  for (const Streamline& line : lines) {
    ASSERT_GE(line.points.size(), 2u);
    ASSERT_EQ(line.faces.size(), line.points.size() - 1);
    for (size_t i = 0; i + 1 < line.points.size(); ++i) {
      const int f = line.faces[i];
      ASSERT_TRUE(f >= 0 && f < s.t().num_faces);
      EXPECT_EQ(singular_faces.count(f), 0u) << "line enters a face of a singular vertex";
      if (i > 0) {
        EXPECT_TRUE(faces_adjacent(s.t(), line.faces[i - 1], f));
      }
      for (const Vector3d& p : {line.points[i], line.points[i + 1]}) {
        const auto [bary, plane] = barycentric(s, f, p);
        worst_bary = std::max({worst_bary, -bary.minCoeff(), bary.maxCoeff() - 1});
        worst_plane = std::max(worst_plane, plane);
      }
      const Vector3d d = line.points[i + 1] - line.points[i];
      if (d.norm() < 1e-12) continue;
      double best = kPi;
      for (int k = 0; k < field.N; ++k) {
        const Vector3d u = s.g().direction_in_face(f, field.angle(f) + 2 * kPi * k / field.N);
        best = std::min(best, std::atan2(d.cross(u).norm(), d.dot(u)));
      }
      worst_angle = std::max(worst_angle, best);
      for (auto [v, n] : s.prescription.vertex)
        nearest_singularity =
            std::min(nearest_singularity, distance_to_segment(s.mesh.V.row(v).transpose(), line.points[i], line.points[i + 1]));
    }
  }
  EXPECT_LE(worst_bary, 1e-9);
  EXPECT_LT(worst_plane, 1e-9 * scale);
  EXPECT_LT(worst_angle, 1e-6);
  EXPECT_GT(nearest_singularity, 1e-6);
}

TEST(Streamlines, StayOnTheSurfaceAndFollowTheField) {
  std::vector<Scene> scenes;
  scenes.push_back(sphere_scene());
  scenes.push_back(cube_scene());
  scenes.push_back(torus_scene());
  scenes.push_back(disk_scene());
  for (const Scene& s : scenes) {
    SCOPED_TRACE("N = " + std::to_string(s.prescription.N) + ", faces " + std::to_string(s.t().num_faces));
    StreamlineOptions o;
    o.separation = 0.08;
    const std::vector<Streamline> lines = trace_streamlines(s.mesh.V, s.t(), s.g(), s.design.field, s.singularities(), o);
    check_streamlines(s, lines);
    double total = 0;
    for (const Streamline& l : lines) total += l.length();
    EXPECT_GT(total, 0.5 * s.g().face_area.sum() / o.separation) << "lines should cover the surface";
  }
}

TEST(Streamlines, CrossFieldTracesBothFamiliesAndIsDeterministic) {
  const Scene s = cube_scene();
  StreamlineOptions o;
  o.separation = 0.1;
  const std::vector<Streamline> a = trace_streamlines(s.mesh.V, s.t(), s.g(), s.design.field, s.singularities(), o);
  const std::vector<Streamline> b = trace_streamlines(s.mesh.V, s.t(), s.g(), s.design.field, s.singularities(), o);
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) EXPECT_TRUE(a[i].points == b[i].points && a[i].faces == b[i].faces);
  // Faces are larger than the separation, so most faces crossed by a line are crossed by a perpendicular one too.
  std::vector<std::vector<Vector3d>> directions(s.t().num_faces);
  for (const Streamline& l : a)
    for (size_t i = 0; i < l.faces.size(); ++i) directions[l.faces[i]].push_back((l.points[i + 1] - l.points[i]).normalized());
  int crossed = 0, with_both = 0;
  for (const auto& d : directions) {
    if (d.empty()) continue;
    ++crossed;
    bool perpendicular = false;
    for (const Vector3d& u : d) perpendicular |= std::abs(u.dot(d[0])) < 1e-6;
    with_both += perpendicular;
  }
  EXPECT_GT(with_both, 0.7 * crossed);
}

TEST(Streamlines, ObjParsesBack) {
  const Scene s = sphere_scene();
  const std::vector<Streamline> lines = trace_streamlines(s.mesh.V, s.t(), s.g(), s.design.field, s.singularities());
  const std::string path = test::temp_dir("streamlines_obj") + "/lines.obj";
  write_streamlines_obj(path, lines);
  std::istringstream in(slurp(path));
  std::string row;
  size_t vertices = 0, polylines = 0, expected_vertices = 0;
  std::vector<Vector3d> v;
  while (std::getline(in, row)) {
    std::istringstream fields(row);
    std::string tag;
    fields >> tag;
    if (tag == "v") {
      Vector3d p;
      fields >> p.x() >> p.y() >> p.z();
      v.push_back(p);
      ++vertices;
    } else if (tag == "l") {
      const Streamline& line = lines.at(polylines++);
      size_t index = 0, count = 0;
      while (fields >> index) {
        ASSERT_TRUE(index >= 1 && index <= v.size());
        EXPECT_EQ(v[index - 1], line.points[count++]);
      }
      EXPECT_EQ(count, line.points.size());
    }
  }
  for (const Streamline& l : lines) expected_vertices += l.points.size();
  EXPECT_EQ(vertices, expected_vertices);
  EXPECT_EQ(polylines, lines.size());
}

std::pair<int, int> png_size(const std::string& bytes) {
  auto be32 = [&](size_t at) {
    return int((unsigned char)bytes[at]) << 24 | int((unsigned char)bytes[at + 1]) << 16 | int((unsigned char)bytes[at + 2]) << 8 |
           int((unsigned char)bytes[at + 3]);
  };
  if (bytes.size() < 24 || bytes.compare(0, 8, "\x89PNG\r\n\x1a\n") != 0) return {-1, -1};
  return {be32(16), be32(20)};
}

TEST(RenderCli, WritesAPngOfTheRequestedSize) {
  const std::string dir = test::temp_dir("render_cli");
  const Mesh m = make_cube_sphere(4, true);
  write_obj(dir + "/cube.obj", m.V, m.F);
  std::string sings;
  for (auto [v, n] : cube_scene(4).prescription.vertex) sings += " --sing " + std::to_string(v) + ":1/4";
  const test::CommandResult solved = test::run_cli("solve '" + dir + "/cube.obj' -N 4" + sings + " --field-out '" + dir + "/f.txt' -q");
  ASSERT_EQ(solved.status, 0) << solved.err;

  const test::CommandResult r =
      test::run_cli("render '" + dir + "/cube.obj' --field '" + dir + "/f.txt' -o '" + dir +
                    "/a.png' --size 320x240 --view 45,30 --style streamlines --streamlines-out '" + dir + "/lines.obj'");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(png_size(slurp(dir + "/a.png")), std::make_pair(320, 240));
  const std::string obj = slurp(dir + "/lines.obj");
  EXPECT_NE(obj.find("\nv "), std::string::npos);
  EXPECT_NE(obj.find("\nl "), std::string::npos);

  // Default size, singularities from the field itself, hedgehog.
  const test::CommandResult d = test::run_cli("render '" + dir + "/cube.obj' --field '" + dir + "/f.txt' -o '" + dir + "/b.png'");
  ASSERT_EQ(d.status, 0) << d.err;
  EXPECT_EQ(png_size(slurp(dir + "/b.png")), std::make_pair(1200, 900));
}

TEST(RenderCli, FailsClearlyOnBadInput) {
  const std::string dir = test::temp_dir("render_cli_bad");
  const Mesh m = make_icosphere(1);
  write_obj(dir + "/ico.obj", m.V, m.F);
  const test::CommandResult missing = test::run_cli("render '" + dir + "/ico.obj' --field '" + dir + "/nope.txt' -o '" + dir + "/x.png'");
  EXPECT_NE(missing.status, 0);
  EXPECT_NE(missing.err.find("trivcon: error: "), std::string::npos) << missing.err;
  EXPECT_NE(missing.err.find(dir + "/nope.txt"), std::string::npos) << missing.err;
  EXPECT_FALSE(std::ifstream(dir + "/x.png").good());

  ASSERT_EQ(test::run_cli("solve '" + dir + "/ico.obj' --sing 0:1 --sing 3:1 --field-out '" + dir + "/f.txt' -q").status, 0);
  const test::CommandResult bad_size =
      test::run_cli("render '" + dir + "/ico.obj' --field '" + dir + "/f.txt' -o '" + dir + "/x.png' --size 12by3");
  EXPECT_NE(bad_size.status, 0);
  EXPECT_NE(bad_size.err.find("--size 12by3"), std::string::npos) << bad_size.err;
  const test::CommandResult bad_vertex =
      test::run_cli("render '" + dir + "/ico.obj' --field '" + dir + "/f.txt' -o '" + dir + "/x.png' --sing 999:1");
  EXPECT_NE(bad_vertex.status, 0);
  EXPECT_NE(bad_vertex.err.find("999"), std::string::npos) << bad_vertex.err;
}

}  // namespace
}  // namespace trivcon

namespace trivcon {
namespace {

// polygon_edges: the edges of the file's polygons, not the diagonals of their fans (two quads side by side:
// 7 edges of 9), and every edge when the triangles are the file's own.
TEST(PolygonEdges, LeavesOutTheFansDiagonals) {
  MatrixX3i F(4, 3);
  F << 0, 1, 4, 0, 4, 3, 1, 2, 5, 1, 5, 4;
  const Topology t = build_topology(F, 6);
  const std::vector<int> quads = polygon_edges(t, {0, 0, 1, 1});
  EXPECT_EQ(quads.size(), 7u);
  for (int e : quads) {
    const std::pair<int, int> ends(t.edge_vertices(e, 0), t.edge_vertices(e, 1));
    EXPECT_NE(ends, std::make_pair(0, 4));
    EXPECT_NE(ends, std::make_pair(1, 5));
  }
  EXPECT_EQ(polygon_edges(t, {}).size(), 9u);
}

}  // namespace
}  // namespace trivcon
