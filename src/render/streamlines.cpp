// SPDX-License-Identifier: MIT
#include "trivcon/streamlines.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <iomanip>
#include <limits>
#include <ostream>
#include <random>
#include <unordered_map>

#include "trivcon/error.h"
#include "trivcon/io.h"

namespace trivcon {

namespace {

constexpr double kVertexTolerance = 1e-6;  // fraction of an edge: closer to an end counts as hitting the vertex
constexpr double kInwardTolerance = 1e-9;  // a direction must enter a face at least this steeply (sine)

using Vector2d = Eigen::Vector2d;
using Vector3d = Eigen::Vector3d;

Vector3d vertex(const MatrixX3d& V, int v) { return V.row(v).transpose(); }

double bounding_diagonal(const MatrixX3d& V, const Topology& t) {
  Vector3d lo = Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (int v = 0; v < t.num_vertices; ++v) {
    if (t.vertex_component[v] < 0) continue;
    lo = lo.cwiseMin(vertex(V, v));
    hi = hi.cwiseMax(vertex(V, v));
  }
  return t.num_faces > 0 ? (hi - lo).norm() : 0.0;
}

// A hash grid of points, for "is any accepted point within r of p" queries with r ≤ the cell size.
struct GridEntry {
  Vector3d position;
  Vector3d tangent;  // unit; zero for plain points
  int line = -1;
  double arc = 0;  // signed arc length from the line's seed
};

class PointGrid {
 public:
  explicit PointGrid(double cell) : cell_(cell) {}

  std::uint64_t insert(const GridEntry& e) {
    const std::uint64_t key = key_of(cell_of(e.position));
    cells_[key].push_back(e);
    return key;
  }
  // Undoes the latest insert into the cell `key` (inserts are undone in reverse order).
  void remove_last(std::uint64_t key) {
    auto it = cells_.find(key);
    it->second.pop_back();
    if (it->second.empty()) cells_.erase(it);
  }
  template <class Accept>
  bool any_within(const Vector3d& p, double r, const Accept& accept) const {
    const std::array<std::int64_t, 3> c = cell_of(p);
    for (std::int64_t dx = -1; dx <= 1; ++dx)
      for (std::int64_t dy = -1; dy <= 1; ++dy)
        for (std::int64_t dz = -1; dz <= 1; ++dz) {
          auto it = cells_.find(key_of({c[0] + dx, c[1] + dy, c[2] + dz}));
          if (it == cells_.end()) continue;
          for (const GridEntry& e : it->second)
            if ((e.position - p).squaredNorm() < r * r && accept(e)) return true;
        }
    return false;
  }

 private:
  std::array<std::int64_t, 3> cell_of(const Vector3d& p) const {
    return {static_cast<std::int64_t>(std::floor(p.x() / cell_)), static_cast<std::int64_t>(std::floor(p.y() / cell_)),
            static_cast<std::int64_t>(std::floor(p.z() / cell_))};
  }
  static std::uint64_t key_of(const std::array<std::int64_t, 3>& c) {
    // Collisions only cost time: queries check real distances.
    std::uint64_t h = 1469598103934665603ull;
    for (std::int64_t x : c) h = (h ^ static_cast<std::uint64_t>(x)) * 1099511628211ull;
    return h;
  }
  double cell_;
  std::unordered_map<std::uint64_t, std::vector<GridEntry>> cells_;
};

// Uniform double in (0, 1) from a std::mt19937 draw (the same on every platform, unlike std::uniform_*).
double unit_draw(std::mt19937& rng) { return (static_cast<double>(rng()) + 0.5) / 4294967296.0; }

// Candidate points spread over the usable faces by area, about four per spacing², in a fixed
// pseudo-random order: faces are visited in shuffled order and a point is emitted each time the
// accumulated area passes another spacing²/4, so big faces get several points and tiny faces a share.
std::vector<SurfacePoint> area_candidates(const MatrixX3d& V, const Topology& t, const Geometry& g, double spacing,
                                          const std::vector<char>& usable) {
  std::mt19937 rng(20100719u);
  std::vector<int> order(t.num_faces);
  for (int f = 0; f < t.num_faces; ++f) order[f] = f;
  for (int i = t.num_faces - 1; i > 0; --i) std::swap(order[i], order[rng() % static_cast<unsigned>(i + 1)]);
  const double area_per_point = spacing * spacing / 4;
  std::vector<SurfacePoint> out;
  double accumulated = unit_draw(rng);
  for (int f : order) {
    if (g.degenerate_face[f] || (!usable.empty() && !usable[f])) continue;
    accumulated += g.face_area(f) / area_per_point;
    for (; accumulated >= 1; accumulated -= 1) {
      double a = unit_draw(rng), b = unit_draw(rng);
      if (a + b > 1) a = 1 - a, b = 1 - b;  // fold the square onto the triangle: uniform by area
      const Vector3d p0 = vertex(V, t.F(f, 0)), p1 = vertex(V, t.F(f, 1)), p2 = vertex(V, t.F(f, 2));
      out.push_back({f, (1 - a - b) * p0 + a * p1 + b * p2});
    }
  }
  return out;
}

// Corners of face f in its own frame (trivcon/geometry.h): counter-clockwise, corner 0 at the origin.
std::array<Vector2d, 3> corners_2d(const MatrixX3d& V, const Topology& t, const Geometry& g, int f) {
  const Vector3d p0 = vertex(V, t.F(f, 0));
  std::array<Vector2d, 3> c;
  for (int k = 0; k < 3; ++k) {
    const Vector3d d = vertex(V, t.F(f, k)) - p0;
    c[k] = Vector2d(d.dot(g.frame_x.row(f)), d.dot(g.frame_y.row(f)));
  }
  return c;
}

// Outward (unnormalised, length = edge length) normal of edge k of a counter-clockwise triangle.
Vector2d outward_normal(const std::array<Vector2d, 3>& c, int k) {
  const Vector2d e = c[(k + 1) % 3] - c[k];
  return Vector2d(e.y(), -e.x());
}

class Tracer {
 public:
  Tracer(const MatrixX3d& V, const Topology& t, const Geometry& g, const Field& field,
         const std::vector<std::pair<int, int>>& singularities, const StreamlineOptions& o)
      : V_(V),
        t_(t),
        g_(g),
        field_(field),
        separation_(o.separation > 0 ? o.separation : bounding_diagonal(V, t) / 50),
        max_length_(o.max_length > 0 ? o.max_length : 10 * bounding_diagonal(V, t)),
        sample_step_(separation_ / 4),
        parallel_cos_(parallel_cosine(field.N)),
        max_steps_(o.max_steps),
        all_families_(o.all_families),
        grid_(separation_),
        blocked_(g.degenerate_face) {
    for (const auto& singularity : singularities) {
      const int v = singularity.first;
      if (v < 0 || v >= t.num_vertices) throw Error("singular vertex " + std::to_string(v) + " out of range");
      for (int a = t.vertex_face_offsets[v]; a < t.vertex_face_offsets[v + 1]; ++a) blocked_[t.vertex_faces[a]] = 1;
    }
  }

  std::vector<Streamline> run() {
    std::vector<Streamline> lines;
    if (!(separation_ > 0)) return lines;  // no faces
    const int N = field_.N;
    const int families = !all_families_ ? 1 : (N % 2 == 0 ? N / 2 : N);
    std::vector<char> usable(blocked_.size());
    for (size_t f = 0; f < usable.size(); ++f) usable[f] = !blocked_[f];
    for (const SurfacePoint& seed : area_candidates(V_, t_, g_, separation_, usable)) {
      for (int k = 0; k < families; ++k) {
        const double beta = field_.angle(seed.face) + 2 * kPi * k / N;
        Streamline line;
        if (trace_line(seed, beta, static_cast<int>(lines.size()), line)) lines.push_back(std::move(line));
      }
    }
    return lines;
  }

 private:
  // Where a line is: in `face` at 2D point `q` (face frame), world point `x`, having entered through
  // edge `entry` (−1 at the seed), following the field direction at angle `tangent` in the face's frame.
  struct Cursor {
    int face;
    Vector2d q;
    Vector3d x;
    int entry;
    double tangent;
  };
  struct HalfLine {
    std::vector<Vector3d> points;  // after the seed
    std::vector<int> faces;        // faces[i]: face of the segment ending at points[i]
    double length = 0;
  };

  bool trace_line(const SurfacePoint& seed, double beta, int id, Streamline& out) {
    const Vector3d tangent = g_.direction_in_face(seed.face, beta);
    if (near_other_line(seed.position, tangent, id, 0, separation_)) return false;
    std::vector<std::uint64_t> inserted{grid_.insert({seed.position, tangent, id, 0})};
    const Vector3d d = seed.position - vertex(V_, t_.F(seed.face, 0));
    const Cursor start{seed.face, Vector2d(d.dot(g_.frame_x.row(seed.face)), d.dot(g_.frame_y.row(seed.face))), seed.position, -1, beta};
    HalfLine forward, backward;
    trace_half(start, +1, id, forward, inserted);
    trace_half(start, -1, id, backward, inserted);
    if (forward.length + backward.length < separation_) {
      for (auto it = inserted.rbegin(); it != inserted.rend(); ++it) grid_.remove_last(*it);
      return false;
    }
    out.points.assign(backward.points.rbegin(), backward.points.rend());
    out.faces.assign(backward.faces.rbegin(), backward.faces.rend());
    out.points.push_back(seed.position);
    out.points.insert(out.points.end(), forward.points.begin(), forward.points.end());
    out.faces.insert(out.faces.end(), forward.faces.begin(), forward.faces.end());
    return true;
  }

  // Follows the field from `c` (sign +1: along the tangent, −1: against it) until a stopping rule applies.
  void trace_half(Cursor c, int sign, int id, HalfLine& out, std::vector<std::uint64_t>& inserted) {
    for (int step = 0; step < max_steps_ && out.length < max_length_; ++step) {
      const std::array<Vector2d, 3> corners = corners_2d(V_, t_, g_, c.face);
      const double motion = c.tangent + (sign < 0 ? kPi : 0);
      const Vector2d m(std::cos(motion), std::sin(motion));
      int k = -1;
      double s = 0;
      if (!exit_edge(corners, c, m, k, s)) return;
      const int a = t_.F(c.face, k), b = t_.F(c.face, (k + 1) % 3);
      const Vector3d exit = (1 - s) * vertex(V_, a) + s * vertex(V_, b);
      if (!add_segment(c, exit, sign, id, out, inserted)) return;
      if (s < kVertexTolerance || s > 1 - kVertexTolerance) return;  // at a vertex: the next face is ambiguous
      if (!cross_edge(c, k, s, exit, sign)) return;
    }
  }

  // The edge k (≠ c.entry) where the ray from c.q along m leaves the face, and the position s ∈ [0, 1] along it.
  static bool exit_edge(const std::array<Vector2d, 3>& corners, const Cursor& c, const Vector2d& m, int& k, double& s) {
    double best = std::numeric_limits<double>::infinity();
    for (int j = 0; j < 3; ++j) {
      if (j == c.entry) continue;
      const Vector2d n = outward_normal(corners, j);
      const double towards = m.dot(n);
      if (!(towards > 0)) continue;
      const double hit = std::max(0.0, (corners[j] - c.q).dot(n) / towards);
      if (hit < best) best = hit, k = j;
    }
    if (k < 0) return false;
    const Vector2d e = corners[(k + 1) % 3] - corners[k];
    s = std::clamp((c.q + best * m - corners[k]).dot(e) / e.squaredNorm(), 0.0, 1.0);
    return true;
  }

  // Moves the cursor across edge k of its face at position s; false when the line must stop there.
  bool cross_edge(Cursor& c, int k, double s, const Vector3d& exit, int sign) const {
    const int e = t_.face_edges(c.face, k);
    const bool from_left = t_.edge_faces(e, 0) == c.face;
    const int next = t_.edge_faces(e, from_left ? 1 : 0);
    if (next < 0 || blocked_[next]) return false;
    int kn = 0;
    while (t_.face_edges(next, kn) != e) ++kn;
    const std::array<Vector2d, 3> corners = corners_2d(V_, t_, g_, next);
    // The shared edge runs the other way in the neighbour (consistent orientation).
    const Vector2d q = corners[kn] + (1 - s) * (corners[(kn + 1) % 3] - corners[kn]);
    const double carried = c.tangent + (from_left ? g_.rho(e) : -g_.rho(e));
    const double period = 2 * kPi / field_.N;
    const double tangent = field_.angle(next) + period * std::round((carried - field_.angle(next)) / period);
    const double motion = tangent + (sign < 0 ? kPi : 0);
    const Vector2d n = outward_normal(corners, kn);
    if (!(Vector2d(std::cos(motion), std::sin(motion)).dot(n) < -kInwardTolerance * n.norm())) return false;  // field turns back
    c = Cursor{next, q, exit, kn, tangent};
    return true;
  }

  // Appends the segment c.x → `end` in c.face, checking it against the other lines every sample_step;
  // where it comes too close, the line ends at the last sample that did not (false: stop tracing).
  bool add_segment(const Cursor& c, const Vector3d& end, int sign, int id, HalfLine& out, std::vector<std::uint64_t>& inserted) {
    const Vector3d tangent = g_.direction_in_face(c.face, c.tangent);
    const double length = (end - c.x).norm();
    const int pieces = std::max(1, static_cast<int>(std::ceil(length / sample_step_)));
    for (int j = 1; j <= pieces; ++j) {
      const Vector3d p = j == pieces ? end : Vector3d(c.x + (end - c.x) * (static_cast<double>(j) / pieces));
      const double arc = sign * (out.length + length * j / pieces);
      if (near_other_line(p, tangent, id, arc, separation_ / 2)) {
        if (j > 1) append(out, c.x + (end - c.x) * (static_cast<double>(j - 1) / pieces), c.face, length * (j - 1) / pieces);
        return false;
      }
      inserted.push_back(grid_.insert({p, tangent, id, arc}));
    }
    append(out, end, c.face, length);
    return true;
  }

  static void append(HalfLine& out, const Vector3d& p, int face, double length) {
    out.points.push_back(p);
    out.faces.push_back(face);
    out.length += length;
  }

  // A near-parallel sample of another line (or of this one, more than 2 separations away along it) within r of p.
  bool near_other_line(const Vector3d& p, const Vector3d& tangent, int id, double arc, double r) const {
    return grid_.any_within(p, r, [&](const GridEntry& e) {
      if (e.line == id && std::abs(e.arc - arc) <= 2 * separation_) return false;
      return std::abs(e.tangent.dot(tangent)) > parallel_cos_;
    });
  }

  // Lines are near-parallel when closer in angle than half the gap between the field's line families
  // (2π/N for even N, π/N for odd N, as unoriented lines), at most 60°.
  static double parallel_cosine(int N) {
    const double family_gap = N % 2 == 0 ? 2 * kPi / N : kPi / N;
    return std::cos(std::min(family_gap / 2, kPi / 3));
  }

  const MatrixX3d& V_;
  const Topology& t_;
  const Geometry& g_;
  const Field& field_;
  const double separation_, max_length_, sample_step_, parallel_cos_;
  const int max_steps_;
  const bool all_families_;
  PointGrid grid_;
  std::vector<char> blocked_;  // faces that end a line: degenerate, or with a singular corner
};

}  // namespace

double Streamline::length() const {
  double sum = 0;
  for (size_t i = 1; i < points.size(); ++i) sum += (points[i] - points[i - 1]).norm();
  return sum;
}

std::vector<Streamline> trace_streamlines(const MatrixX3d& V, const Topology& topology, const Geometry& geometry, const Field& field,
                                          const std::vector<std::pair<int, int>>& singularities, const StreamlineOptions& options) {
  if (field.angle.size() != topology.num_faces)
    throw Error("trace_streamlines: the field has " + std::to_string(field.angle.size()) + " faces, the mesh " +
                std::to_string(topology.num_faces));
  if (field.N < 1) throw Error("trace_streamlines: field N must be at least 1");
  return Tracer(V, topology, geometry, field, singularities, options).run();
}

void write_streamlines_obj(const std::string& path, const std::vector<Streamline>& lines) {
  write_file_atomically(path, [&](std::ostream& out) {
    out << "# trivcon streamlines: " << lines.size() << " polylines\n" << std::setprecision(17);
    for (const Streamline& line : lines)
      for (const Vector3d& p : line.points) out << "v " << p.x() << " " << p.y() << " " << p.z() << "\n";
    size_t next = 1;
    for (const Streamline& line : lines) {
      out << "l";
      for (size_t i = 0; i < line.points.size(); ++i) out << " " << next++;
      out << "\n";
    }
  });
}

std::vector<SurfacePoint> sample_surface(const MatrixX3d& V, const Topology& topology, const Geometry& geometry, double spacing,
                                         const std::vector<char>& usable) {
  if (!(spacing > 0)) throw Error("sample_surface: spacing must be positive");
  PointGrid grid(spacing);
  std::vector<SurfacePoint> out;
  for (const SurfacePoint& p : area_candidates(V, topology, geometry, spacing, usable)) {
    if (grid.any_within(p.position, spacing, [](const GridEntry&) { return true; })) continue;
    grid.insert({p.position, Vector3d::Zero(), -1, 0});
    out.push_back(p);
  }
  return out;
}

}  // namespace trivcon
