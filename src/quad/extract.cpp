// SPDX-License-Identifier: MIT
// The quad mesh of an integer-grid map (trivcon/quad.h; the steps and the folds: docs/quad.md).
//
// Stages: exact charts (the map's (u, v) as whole multiples of 2⁻²⁰, one value per vertex carried around its fan
// through the cut's transitions), the integer points (at vertices, inside edges, inside positive faces), the
// directions leaving each point (counter-clockwise), one trace per direction along the iso-line to the integer
// point one unit away (across faces, through vertices, along edges, through the transitions), and the faces of
// the traced graph walked by turning at each point to the direction just clockwise of the one the walk came in by.
#include "trivcon/quad.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <sstream>

#include "linalg/timing.h"
#include "quad/fill.h"
#include "quad/relax.h"
#include "trivcon/error.h"

namespace trivcon {

namespace {

using i64 = long long;
using i128 = __int128;

constexpr i64 kUnit = i64{1} << 20;           // one unit of (u, v) in chart coordinates
constexpr double kLargest = 1073741824.0;     // 2³⁰: |u|, |v| beyond this would overflow the exact predicates
constexpr double kMostSquares = 134217728.0;  // 2²⁷: the most unit squares the faces' (u, v) boxes may cover

struct P2 {
  i64 x = 0, y = 0;
};
P2 operator+(P2 a, P2 b) { return {a.x + b.x, a.y + b.y}; }
P2 operator-(P2 a, P2 b) { return {a.x - b.x, a.y - b.y}; }
P2 operator*(P2 a, i64 s) { return {a.x * s, a.y * s}; }
bool operator==(P2 a, P2 b) { return a.x == b.x && a.y == b.y; }
bool operator!=(P2 a, P2 b) { return !(a == b); }
i128 cross(P2 a, P2 b) { return static_cast<i128>(a.x) * b.y - static_cast<i128>(a.y) * b.x; }
i128 dot(P2 a, P2 b) { return static_cast<i128>(a.x) * b.x + static_cast<i128>(a.y) * b.y; }
int sign(i128 a) { return a > 0 ? 1 : (a < 0 ? -1 : 0); }
bool whole(P2 p) { return p.x % kUnit == 0 && p.y % kUnit == 0; }

// Direction codes: 0 = +u, 1 = +v, 2 = −u, 3 = −v; J (the quarter turn counter-clockwise) adds 1.
P2 unit(int code) {
  static constexpr std::array<P2, 4> d{P2{1, 0}, P2{0, 1}, P2{-1, 0}, P2{0, -1}};
  return d[code & 3];
}
int turn(int code, int r) { return ((code + r) % 4 + 4) % 4; }
// J^r p.
P2 rotate(int r, P2 p) {
  switch (((r % 4) + 4) % 4) {
    case 1:
      return {-p.y, p.x};
    case 2:
      return {-p.x, -p.y};
    case 3:
      return {p.y, -p.x};
    default:
      return p;
  }
}
// The code of an axis-parallel non-zero vector, −1 for any other.
int code_of(P2 w) {
  if (w.y == 0 && w.x != 0) return w.x > 0 ? 0 : 2;
  if (w.x == 0 && w.y != 0) return w.y > 0 ? 1 : 3;
  return -1;
}
i64 floor_div(i64 a, i64 b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }
i64 ceil_div(i64 a, i64 b) { return -floor_div(-a, b); }

// Sorts the first n (at most 4) codes counter-clockwise, all lying within less than a half turn of each other.
void sort_counter_clockwise(std::array<int, 4>& codes, int n) {
  for (int i = 1; i < n; ++i)
    for (int j = i; j > 0 && cross(unit(codes[j]), unit(codes[j - 1])) > 0; --j) std::swap(codes[j], codes[j - 1]);
}

struct Slot {
  int face = -1, code = 0;  // the direction `code` in the chart of `face`
};

enum class Kind { kVertex, kEdge, kFace };

struct Node {
  Kind kind = Kind::kFace;
  int element = -1;  // the vertex, edge or face
  int face = -1;     // the chart p is in (for an edge: its L face, or its only face)
  P2 p;
  bool boundary = false;  // its directions do not go all the way round (on the input's boundary)
};

// Where a trace is, between steps.
struct State {
  enum Mode { kInFace, kAlongEdge, kDone, kFailed } mode = kFailed;
  int face = -1;
  int code = 0;                            // direction of travel in face's chart
  P2 target;                               // the integer point one unit from the start, in face's chart
  int entry_edge = -1, entry_vertex = -1;  // kInFace: what the trace came in by (−1: started inside)
  int local_edge = -1;                     // kAlongEdge: the face's edge from corner k to k + 1 it runs along
  int end_slot = -1;                       // kDone: the slot (global) at the end point pointing back
};

class Extractor {
 public:
  Extractor(const FieldDesigner& designer, const Parametrization& param, const QuadOptions& options)
      : designer_(designer), t_(designer.topology()), V_(designer.V()), param_(param), options_(options) {}

  QuadMesh run();

 private:
  int other_face(int e, int f) const { return t_.edge_faces(e, 0) == f ? t_.edge_faces(e, 1) : t_.edge_faces(e, 0); }
  int chart_face(int e) const { return t_.edge_faces(e, 0) >= 0 ? t_.edge_faces(e, 0) : t_.edge_faces(e, 1); }
  const P2& at(int f, int k) const { return U_[3 * f + ((k % 3) + 3) % 3]; }
  // A point and a direction code of `from`'s chart in the chart of the face across edge e: φ_R = J^r φ_L + t.
  P2 across(int e, int from, P2 p) const {
    if (!cut_[e]) return p;
    const int r = param_.rotation[e];
    const P2 shift{param_.translation(e, 0) * kUnit, param_.translation(e, 1) * kUnit};
    return from == t_.edge_faces(e, 0) ? rotate(r, p) + shift : rotate(-r, p - shift);
  }
  int across_code(int e, int from, int code) const {
    if (!cut_[e]) return code;
    return from == t_.edge_faces(e, 0) ? turn(code, param_.rotation[e]) : turn(code, -param_.rotation[e]);
  }

  void build_fans();
  void build_charts();
  void join_points();
  void find_points();
  // The corner of face f at vertex v or at a vertex joined to it (join_points; v the first of them).
  // Whether face f's (u, v) triangle has zero area (a face holding an edge of length 0 maps to a segment).
  bool flat(int f) const { return cross(at(f, 1) - at(f, 0), at(f, 2) - at(f, 0)) == 0; }
  int corner_at(int v, int f) const {
    for (int k = 0; k < 3; ++k)
      if (joined_[t_.F(f, k)] == v) return k;
    return -1;
  }
  void fan_slots(int v, std::vector<Slot>& out) const;
  void edge_slots(int e, std::vector<Slot>& out) const;
  int find_slot(int node, int face, int code) const;
  int arrive_at_vertex(int node, int face, int code) const;
  int arrive(int node, int face, int code) const;
  int node_at(int begin, int end, P2 p) const;
  int node_on_edge(int e, int face, P2 p) const;
  int node_in_face(int f, P2 p) const;
  State start(int node, int slot) const;
  State through_vertex(int v, int face, int code, P2 target) const;
  void step(State& s) const;
  int trace(int node, int slot) const;
  // Keeps the first few input faces where something failed, for the report.
  void note(int face) const {
    if (face >= 0 && q_.problem_faces.size() < 10 &&
        std::find(q_.problem_faces.begin(), q_.problem_faces.end(), face) == q_.problem_faces.end())
      q_.problem_faces.push_back(face);
  }
  Eigen::Vector3d barycentric(const Node& n, int& face) const;

  const FieldDesigner& designer_;
  const Topology& t_;
  const MatrixX3d& V_;
  const Parametrization& param_;
  const QuadOptions& options_;
  std::vector<char> cut_;
  std::vector<int> fan_offsets_, fan_faces_, fan_corners_;  // fan_corners_: the corner of each fan face at the vertex
  std::vector<int> joined_;                  // per vertex: the first vertex of its joined point (join_points), else itself
  std::vector<char> boundary_fan_;           // per vertex: its (joined) fan starts and ends at the boundary
  std::vector<P2> U_;
  std::vector<char> positive_;
  std::vector<Node> nodes_;
  std::vector<int> vertex_node_, edge_node_offsets_, face_node_offsets_;
  std::vector<int> slot_offsets_;  // per node, into slots_
  std::vector<Slot> slots_;
  std::vector<int> slot_node_;
  mutable long long steps_ = 0, step_budget_ = 0;  // faces and edges crossed by all traces, and their limit
  mutable QuadQuality q_;
};

// The faces around each vertex, counter-clockwise; a boundary vertex's start with the face whose edge from the
// vertex to its next corner is on the boundary (vertex_fan).
void Extractor::build_fans() {
  const int nV = t_.num_vertices;
  fan_offsets_.assign(nV + 1, 0);
  fan_faces_.reserve(3 * static_cast<size_t>(t_.num_faces));
  std::vector<int> fan;
  for (int v = 0; v < nV; ++v) {
    fan_offsets_[v] = static_cast<int>(fan_faces_.size());
    vertex_fan(t_, v, fan);
    for (int f : fan) fan_faces_.push_back(f), fan_corners_.push_back(t_.corner_of(f, v));
  }
  fan_offsets_[nV] = static_cast<int>(fan_faces_.size());
  joined_.resize(nV);
  boundary_fan_.resize(nV);
  for (int v = 0; v < nV; ++v) joined_[v] = v, boundary_fan_[v] = t_.is_boundary_vertex(v);
}

// Vertices at one point of the surface and of the map (ends of an edge of length 0 with one chart value, an integer
// point: the pole row of a sphere exported unwelded, whose map ties them, docs/param.md) are one point of the quad
// mesh. The first of them (smallest id) takes their fans joined in order (b's after a's where a's last face is b's
// first: the face holding both); the others keep none. Where the fans do not chain so, the vertices stay apart.
void Extractor::join_points() {
  const int nV = t_.num_vertices;
  std::vector<int> parent(nV);
  for (int v = 0; v < nV; ++v) parent[v] = v;
  auto find = [&](int v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
  };
  bool any = false;
  for (int e = 0; e < t_.num_edges; ++e) {
    const int a = t_.edge_vertices(e, 0), b = t_.edge_vertices(e, 1);
    if (!zero_length_edge(V_, t_, e)) continue;
    const int f = chart_face(e);
    const P2 pa = at(f, t_.corner_of(f, a));
    if (pa != at(f, t_.corner_of(f, b)) || !whole(pa)) continue;
    const int ra = find(a), rb = find(b);
    if (ra != rb) parent[std::max(ra, rb)] = std::min(ra, rb), any = true;
  }
  if (!any) return;
  std::vector<std::vector<int>> members(nV);
  for (int v = 0; v < nV; ++v) members[find(v)].push_back(v);
  std::vector<std::vector<std::pair<int, int>>> fans(nV);  // (face, corner) per vertex, as they will be
  for (int v = 0; v < nV; ++v)
    for (int j = fan_offsets_[v]; j < fan_offsets_[v + 1]; ++j) fans[v].push_back({fan_faces_[j], fan_corners_[j]});
  for (int root = 0; root < nV; ++root) {
    const std::vector<int>& m = members[root];
    if (m.size() < 2) continue;
    bool empty = false;
    for (int v : m) empty |= fans[v].empty();
    if (empty) continue;
    std::multimap<int, int> starting;  // first fan face → member (a fan of one face starts and ends with it)
    for (int v : m) starting.emplace(fans[v].front().first, v);
    auto next = [&](int v) {
      const auto [lo, hi] = starting.equal_range(fans[v].back().first);
      for (auto it = lo; it != hi; ++it)
        if (it->second != v) return it->second;
      return -1;
    };
    std::map<int, int> before;
    for (int v : m)
      if (const int w = next(v); w >= 0) before[w] = v;
    int start = m.front();
    for (int v : m)
      if (!before.count(v)) start = v;
    const bool cycle = static_cast<int>(before.size()) == static_cast<int>(m.size());
    std::vector<int> order{start};
    for (int w = next(start); w >= 0 && w != start && order.size() <= m.size(); w = next(w)) order.push_back(w);
    if (order.size() != m.size()) continue;
    std::vector<std::pair<int, int>> fan;
    for (int v : order)
      for (const auto& entry : fans[v])
        if (fan.empty() || fan.back().first != entry.first) fan.push_back(entry);
    if (cycle && fan.size() > 1 && fan.back().first == fan.front().first) fan.pop_back();
    for (int v : m) fans[v].clear(), joined_[v] = root;
    fans[root] = std::move(fan);
    boundary_fan_[root] = !cycle;
  }
  fan_faces_.clear(), fan_corners_.clear();
  for (int v = 0; v < nV; ++v) {
    fan_offsets_[v] = static_cast<int>(fan_faces_.size());
    for (auto [f, k] : fans[v]) fan_faces_.push_back(f), fan_corners_.push_back(k);
  }
  fan_offsets_[nV] = static_cast<int>(fan_faces_.size());
}

// One exact value per vertex: its first fan corner's (u, v) in units of 2⁻²⁰, carried to the other corners through
// the transitions, so that every edge's two sides agree exactly.
void Extractor::build_charts() {
  const int nF = t_.num_faces;
  U_.assign(3 * static_cast<size_t>(nF), P2{});
  for (int v = 0; v < t_.num_vertices; ++v) {
    const int begin = fan_offsets_[v], end = fan_offsets_[v + 1];
    if (begin == end) continue;
    int f = fan_faces_[begin], k = t_.corner_of(f, v);
    const double u = param_.uv(3 * f + k, 0), w = param_.uv(3 * f + k, 1);
    if (!std::isfinite(u) || !std::isfinite(w) || std::abs(u) >= kLargest || std::abs(w) >= kLargest)
      throw Error("quad: the map's (u, v) at vertex " + std::to_string(v) + " is not finite or beyond 2^30 in magnitude");
    P2 p{std::llround(u * kUnit), std::llround(w * kUnit)};
    U_[3 * f + k] = p;
    for (int j = begin + 1; j < end; ++j) {
      const int e = t_.face_edges(f, (k + 2) % 3);
      p = across(e, f, p);
      f = fan_faces_[j], k = t_.corner_of(f, v);
      U_[3 * f + k] = p;
    }
    if (t_.is_interior_vertex(v)) {  // around the fan, the transitions must bring the value back
      const int e = t_.face_edges(f, (k + 2) % 3);
      const int first = fan_faces_[begin];
      if (across(e, f, p) != U_[3 * first + t_.corner_of(first, v)]) ++q_.unclosed_vertices;
    }
  }
  positive_.assign(nF, 0);
  for (int f = 0; f < nF; ++f) positive_[f] = cross(at(f, 1) - at(f, 0), at(f, 2) - at(f, 0)) > 0;
}

void Extractor::find_points() {
  const int nV = t_.num_vertices, nE = t_.num_edges, nF = t_.num_faces;
  vertex_node_.assign(nV, -1);
  for (int v = 0; v < nV; ++v) {
    if (fan_offsets_[v] == fan_offsets_[v + 1]) continue;
    const int f = fan_faces_[fan_offsets_[v]];
    const P2 p = at(f, fan_corners_[fan_offsets_[v]]);
    if (!whole(p)) continue;
    vertex_node_[v] = static_cast<int>(nodes_.size());
    nodes_.push_back({Kind::kVertex, v, f, p, boundary_fan_[v] != 0});
  }
  for (int v = 0; v < nV; ++v) vertex_node_[v] = vertex_node_[joined_[v]];
  // Inside edges, in the chart of L (or the only face): whole points strictly between the ends, along the
  // coordinate that changes most.
  edge_node_offsets_.assign(nE + 1, 0);
  for (int e = 0; e < nE; ++e) {
    edge_node_offsets_[e] = static_cast<int>(nodes_.size());
    const int f = chart_face(e);
    const P2 A = at(f, t_.corner_of(f, t_.edge_vertices(e, 0))), B = at(f, t_.corner_of(f, t_.edge_vertices(e, 1)));
    const P2 d = B - A;
    if (d.x == 0 && d.y == 0) continue;
    const bool along_x = std::abs(d.x) >= std::abs(d.y);
    const i64 a = along_x ? A.x : A.y, b = along_x ? B.x : B.y;
    const i64 a_other = along_x ? A.y : A.x, d_major = along_x ? d.x : d.y, d_other = along_x ? d.y : d.x;
    for (i64 m = ceil_div(std::min(a, b), kUnit); m * kUnit <= std::max(a, b); ++m) {
      const double other =
          static_cast<double>(a_other) + static_cast<double>(m * kUnit - a) * static_cast<double>(d_other) / static_cast<double>(d_major);
      const i64 o = std::llround(other / static_cast<double>(kUnit)) * kUnit;
      const P2 p = along_x ? P2{m * kUnit, o} : P2{o, m * kUnit};
      if (cross(d, p - A) != 0 || p == A || p == B) continue;
      nodes_.push_back({Kind::kEdge, e, f, p, t_.is_boundary_edge(e)});
    }
  }
  edge_node_offsets_[nE] = static_cast<int>(nodes_.size());
  auto by_row = [](const Node& a, const Node& b) { return a.p.y != b.p.y ? a.p.y < b.p.y : a.p.x < b.p.x; };
  for (int e = 0; e < nE; ++e) std::sort(nodes_.begin() + edge_node_offsets_[e], nodes_.begin() + edge_node_offsets_[e + 1], by_row);
  // Inside faces: row by row (whole v), the candidates of the row's span tested exactly (so that a face's points
  // come sorted by (v, u), as node_at needs). Points inside a folded
  // or degenerate triangle are counted and dropped. The candidates are bounded by the triangles' boxes: a map
  // whose boxes cover more than 2^27 unit squares is refused before any work (no mesh needs that many quads).
  double boxes = 0;
  for (int f = 0; f < nF; ++f) {
    const P2 A = at(f, 0), B = at(f, 1), C = at(f, 2);
    const double rows = static_cast<double>(std::max({A.y, B.y, C.y}) - std::min({A.y, B.y, C.y})) / kUnit + 1;
    const double columns = static_cast<double>(std::max({A.x, B.x, C.x}) - std::min({A.x, B.x, C.x})) / kUnit + 3;
    boxes += rows * columns;
  }
  if (boxes > kMostSquares) {
    std::ostringstream s;
    s << "quad: the map's (u, v) triangles span about " << boxes << " unit squares (at most 2^27 = " << kMostSquares
      << "): the map is broken, or its edge length far too small for the mesh";
    throw Error(s.str());
  }
  face_node_offsets_.assign(nF + 1, 0);
  for (int f = 0; f < nF; ++f) {
    face_node_offsets_[f] = static_cast<int>(nodes_.size());
    const P2 A = at(f, 0), B = at(f, 1), C = at(f, 2);
    const i64 y0 = ceil_div(std::min({A.y, B.y, C.y}), kUnit), y1 = floor_div(std::max({A.y, B.y, C.y}), kUnit);
    for (i64 row = y0; row <= y1; ++row) {
      const double y = static_cast<double>(row * kUnit);
      double lo = std::numeric_limits<double>::infinity(), hi = -lo;
      for (int k = 0; k < 3; ++k) {
        const P2 a = at(f, k), b = at(f, k + 1);
        if ((a.y < y && b.y < y) || (a.y > y && b.y > y)) continue;
        if (a.y == b.y) {
          lo = std::min({lo, static_cast<double>(a.x), static_cast<double>(b.x)});
          hi = std::max({hi, static_cast<double>(a.x), static_cast<double>(b.x)});
          continue;
        }
        const double x =
            static_cast<double>(a.x) + (y - static_cast<double>(a.y)) * static_cast<double>(b.x - a.x) / static_cast<double>(b.y - a.y);
        lo = std::min(lo, x), hi = std::max(hi, x);
      }
      if (!(lo <= hi)) continue;
      for (i64 col = static_cast<i64>(std::floor(lo / kUnit)) - 1; col <= static_cast<i64>(std::ceil(hi / kUnit)) + 1; ++col) {
        const P2 p{col * kUnit, row * kUnit};
        const int s0 = sign(cross(B - A, p - A)), s1 = sign(cross(C - B, p - B)), s2 = sign(cross(A - C, p - C));
        if (s0 > 0 && s1 > 0 && s2 > 0 && positive_[f]) {
          nodes_.push_back({Kind::kFace, f, f, p, false});
        } else if (s0 != 0 && s0 == s1 && s1 == s2) {
          ++q_.dropped_points;
          note(f);
        }
      }
    }
  }
  face_node_offsets_[nF] = static_cast<int>(nodes_.size());
}

// The directions leaving vertex v, counter-clockwise around its fan: in each positively oriented face, the axis
// directions of its corner's sector from the edge to the next corner (included) to the edge to the previous one
// (excluded, except in a boundary fan's last face, whose edge is the boundary).
void Extractor::fan_slots(int v, std::vector<Slot>& out) const {
  out.clear();
  const int begin = fan_offsets_[v], end = fan_offsets_[v + 1];
  const bool boundary = boundary_fan_[v];
  // A boundary fan's last direction, along the boundary, is its last face's second edge; where the fan ends in faces
  // flat in (u, v) (segments along that edge), the face before them holds it.
  int last = end - 1;
  while (boundary && last > begin && flat(fan_faces_[last])) --last;
  for (int j = begin; j < end; ++j) {
    const int f = fan_faces_[j];
    if (!positive_[f]) continue;
    const int k = fan_corners_[j];
    const P2 p = at(f, k), e1 = at(f, k + 1) - p, e2 = at(f, k + 2) - p;
    std::array<int, 4> codes{};
    int n = 0;
    for (int c = 0; c < 4; ++c) {
      const P2 d = unit(c);
      const bool inside = cross(e1, d) > 0 && cross(d, e2) > 0;
      const bool on_first = cross(e1, d) == 0 && dot(e1, d) > 0;
      const bool on_last = boundary && j == last && cross(e2, d) == 0 && dot(e2, d) > 0;
      if (inside || on_first || on_last) codes[n++] = c;
    }
    sort_counter_clockwise(codes, n);  // from e1 on
    for (int i = 0; i < n; ++i) out.push_back({f, codes[i]});
  }
}

// The directions leaving a point inside edge e, counter-clockwise: along the edge as its chart face holds it, into
// that face, back along the edge, into the other face (in that face's chart).
void Extractor::edge_slots(int e, std::vector<Slot>& out) const {
  out.clear();
  const int f0 = chart_face(e), f1 = other_face(e, f0);
  auto half_edge = [&](int f) {
    for (int k = 0; k < 3; ++k)
      if (t_.face_edges(f, k) == e) return at(f, k + 1) - at(f, k);
    return P2{};
  };
  auto into = [&](int f) {
    if (f < 0 || !positive_[f]) return;
    const P2 w = half_edge(f);
    std::array<int, 4> codes{};
    int n = 0;
    for (int c = 0; c < 4; ++c)
      if (cross(w, unit(c)) > 0) codes[n++] = c;
    sort_counter_clockwise(codes, n);
    for (int i = 0; i < n; ++i) out.push_back({f, codes[i]});
  };
  const int along = code_of(half_edge(f0));
  if (along >= 0) out.push_back({f0, along});
  into(f0);
  if (along >= 0) out.push_back({f0, turn(along, 2)});
  into(f1);
}

int Extractor::find_slot(int node, int face, int code) const {
  for (int s = slot_offsets_[node]; s < slot_offsets_[node + 1]; ++s)
    if (slots_[s].face == face && slots_[s].code == code) return s;
  return -1;
}

// The slot of vertex node `node` for direction `code` of `face`'s chart, a direction in the closed sector of the
// face's corner: one along the sector's second edge belongs to the next face counter-clockwise, unless that face is
// flat in (u, v) (a boundary fan's last direction then stays with this face, fan_slots).
int Extractor::arrive_at_vertex(int node, int face, int code) const {
  const int v = nodes_[node].element, k = corner_at(v, face);
  const P2 e2 = at(face, k + 2) - at(face, k), d = unit(code);
  if (cross(e2, d) == 0 && dot(e2, d) > 0) {
    const int e = t_.face_edges(face, (k + 2) % 3), g = other_face(e, face);
    if (g >= 0 && !flat(g)) return find_slot(node, g, across_code(e, face, code));
  }
  return find_slot(node, face, code);
}

// The slot at `node` for the direction `code` of `face`'s chart (the way back along a trace that ended there).
int Extractor::arrive(int node, int face, int code) const {
  const Node& n = nodes_[node];
  if (n.kind == Kind::kVertex) return arrive_at_vertex(node, face, code);
  if (n.kind == Kind::kEdge && face != n.face) {
    const int e = n.element;
    for (int k = 0; k < 3; ++k)
      if (t_.face_edges(face, k) == e && cross(at(face, k + 1) - at(face, k), unit(code)) == 0)
        return find_slot(node, n.face, across_code(e, face, code));  // along the edge: the chart face's slot
  }
  return find_slot(node, face, code);
}

// The node at p among nodes_[begin, end), which are sorted by (y, x) (a binary search: an element of a broken map
// can hold very many points).
int Extractor::node_at(int begin, int end, P2 p) const {
  const auto first = nodes_.begin() + begin, last = nodes_.begin() + end;
  const auto it = std::lower_bound(first, last, p, [](const Node& n, P2 q) { return n.p.y != q.y ? n.p.y < q.y : n.p.x < q.x; });
  return it != last && it->p == p ? static_cast<int>(it - nodes_.begin()) : -1;
}

int Extractor::node_on_edge(int e, int face, P2 p) const {
  if (face != chart_face(e)) p = across(e, face, p);
  return node_at(edge_node_offsets_[e], edge_node_offsets_[e + 1], p);
}

int Extractor::node_in_face(int f, P2 p) const { return node_at(face_node_offsets_[f], face_node_offsets_[f + 1], p); }

State Extractor::start(int node, int slot) const {
  const Node& n = nodes_[node];
  const Slot& sl = slots_[slot];
  State s;
  s.face = sl.face, s.code = sl.code;
  const P2 d = unit(sl.code);
  if (n.kind == Kind::kFace) {
    s.mode = State::kInFace;
    s.target = n.p + d * kUnit;
    return s;
  }
  if (n.kind == Kind::kEdge) {
    const int e = n.element;
    const P2 p = sl.face == n.face ? n.p : across(e, n.face, n.p);
    s.target = p + d * kUnit;
    for (int k = 0; k < 3; ++k)
      if (t_.face_edges(sl.face, k) == e) {
        if (cross(at(sl.face, k + 1) - at(sl.face, k), d) == 0) {
          s.mode = State::kAlongEdge;
          s.local_edge = k;
        } else {
          s.mode = State::kInFace;
          s.entry_edge = e;
        }
      }
    return s;
  }
  const int k = corner_at(n.element, sl.face), v = t_.F(sl.face, k);
  const P2 p = at(sl.face, k);
  s.target = p + d * kUnit;
  const P2 e1 = at(sl.face, k + 1) - p, e2 = at(sl.face, k + 2) - p;
  if (cross(e1, d) == 0 && dot(e1, d) > 0) {
    s.mode = State::kAlongEdge, s.local_edge = k;
  } else if (cross(e2, d) == 0 && dot(e2, d) > 0) {
    s.mode = State::kAlongEdge, s.local_edge = (k + 2) % 3;
  } else {
    s.mode = State::kInFace, s.entry_vertex = v;
  }
  return s;
}

// An iso-line through vertex v (not an integer point), arriving in `face` with direction `code`: it goes on by
// the direction two quarter turns from the way back, counted around the fan (counter-clockwise, or clockwise
// when the boundary comes first), with the target carried to that face's chart as the distance still to go.
State Extractor::through_vertex(int v, int face, int code, P2 target) const {
  State s;
  std::vector<Slot> fan;
  fan_slots(v, fan);
  const int n = static_cast<int>(fan.size());
  // The way back, in the fan's terms (as arrive_at_vertex).
  int back_face = face, back_code = turn(code, 2);
  {
    const int k = t_.corner_of(face, v);
    const P2 e2 = at(face, k + 2) - at(face, k), d = unit(back_code);
    if (cross(e2, d) == 0 && dot(e2, d) > 0) {
      const int e = t_.face_edges(face, (k + 2) % 3), g = other_face(e, face);
      if (g >= 0 && !flat(g)) back_code = across_code(e, face, back_code), back_face = g;
    }
  }
  int index = -1;
  for (int i = 0; i < n; ++i)
    if (fan[i].face == back_face && fan[i].code == back_code) index = i;
  if (index < 0 || n < 3) return s;
  int next;
  if (!t_.is_boundary_vertex(v)) {
    next = (index + 2) % n;
  } else if (index + 2 < n) {
    next = index + 2;
  } else if (index - 2 >= 0) {
    next = index - 2;
  } else {
    return s;
  }
  const P2 here = at(face, t_.corner_of(face, v));
  const i64 left = static_cast<i64>(dot(target - here, unit(code)));
  const Slot& out = fan[next];
  const int k = t_.corner_of(out.face, v);
  const P2 p = at(out.face, k), d = unit(out.code);
  s.face = out.face, s.code = out.code, s.target = p + d * left;
  const P2 e1 = at(out.face, k + 1) - p, e2 = at(out.face, k + 2) - p;
  if (cross(e1, d) == 0 && dot(e1, d) > 0) {
    s.mode = State::kAlongEdge, s.local_edge = k;
  } else if (cross(e2, d) == 0 && dot(e2, d) > 0) {
    s.mode = State::kAlongEdge, s.local_edge = (k + 2) % 3;
  } else {
    s.mode = State::kInFace, s.entry_vertex = v;
  }
  return s;
}

// One face (or one edge) of a trace: end at the target if it is here, else move on to the next face.
void Extractor::step(State& s) const {
  const int f = s.face;
  const P2 d = unit(s.code), T = s.target;
  const int back = turn(s.code, 2);
  auto finish = [&](int node) {
    if (node < 0) {
      s.mode = State::kFailed;
      return;
    }
    s.end_slot = arrive(node, f, back);
    s.mode = s.end_slot >= 0 ? State::kDone : State::kFailed;
  };
  if (s.mode == State::kAlongEdge) {
    const int k = s.local_edge;
    const P2 a = at(f, k), b = at(f, k + 1);
    const bool forward = dot(b - a, d) > 0;
    const int far = forward ? (k + 1) % 3 : k;
    const i128 to_go = dot(at(f, far) - T, d);
    if (to_go > 0) return finish(node_on_edge(t_.face_edges(f, k), f, T));
    if (to_go == 0) return finish(vertex_node_[t_.F(f, far)]);
    s = through_vertex(t_.F(f, far), f, s.code, T);
    return;
  }
  // In the face: is the target in the closed triangle?
  std::array<int, 3> side{};  // of T against the edge from corner k to k + 1
  for (int k = 0; k < 3; ++k) side[k] = sign(cross(at(f, k + 1) - at(f, k), T - at(f, k)));
  for (int k = 0; k < 3; ++k)
    if (T == at(f, k)) return finish(vertex_node_[t_.F(f, k)]);
  for (int k = 0; k < 3; ++k) {
    if (side[k] != 0) continue;
    const P2 a = at(f, k), b = at(f, k + 1);
    if (dot(T - a, b - a) > 0 && dot(T - b, a - b) > 0) return finish(node_on_edge(t_.face_edges(f, k), f, T));
  }
  if (positive_[f] && side[0] > 0 && side[1] > 0 && side[2] > 0) return finish(node_in_face(f, T));
  // The way out: the corners' sides of the line (σ_k of corner k).
  std::array<int, 3> sigma{};
  for (int k = 0; k < 3; ++k) sigma[k] = sign(cross(d, at(f, k) - T));
  int exit_edge = -1, exit_vertex = -1;
  if (positive_[f]) {
    // Leaving a positive triangle: the edge whose first corner is right of the line and second left, or the
    // corner on the line with the next corner left and the previous right.
    for (int k = 0; k < 3; ++k) {
      if (sigma[k] < 0 && sigma[(k + 1) % 3] > 0) exit_edge = k;
      if (sigma[k] == 0 && sigma[(k + 1) % 3] > 0 && sigma[(k + 2) % 3] < 0) exit_vertex = k;
    }
  } else {
    // A folded or degenerate triangle: whatever the line crosses other than what it came in by.
    int found = 0;
    for (int k = 0; k < 3; ++k) {
      if (sigma[k] * sigma[(k + 1) % 3] < 0 && t_.face_edges(f, k) != s.entry_edge) exit_edge = k, ++found;
      if (sigma[k] == 0 && sigma[(k + 1) % 3] * sigma[(k + 2) % 3] < 0 && t_.F(f, k) != s.entry_vertex) exit_vertex = k, ++found;
    }
    if (found != 1) exit_edge = exit_vertex = -1;
  }
  if (exit_vertex >= 0) {
    s = through_vertex(t_.F(f, exit_vertex), f, s.code, T);
    return;
  }
  if (exit_edge < 0) {
    s.mode = State::kFailed;
    return;
  }
  const int e = t_.face_edges(f, exit_edge), g = other_face(e, f);
  if (g < 0) {  // the iso-line leaves the surface
    s.mode = State::kFailed;
    return;
  }
  s.target = across(e, f, T);
  s.code = across_code(e, f, s.code);
  s.face = g, s.entry_edge = e, s.entry_vertex = -1;
}

// The slot (global) a trace from `slot` of `node` ends at, or −1.
int Extractor::trace(int node, int slot) const {
  State s = start(node, slot);
  const int budget = options_.max_trace_faces > 0 ? options_.max_trace_faces : t_.num_faces + 8;
  for (int i = 0; i < budget && (s.mode == State::kInFace || s.mode == State::kAlongEdge); ++i) {
    // All traces together: a map that folds wildly could otherwise make the work quadratic.
    if (++steps_ > step_budget_) {
      ++q_.abandoned_traces;
      return -1;
    }
    const int face = s.face;
    step(s);
    if (s.mode == State::kFailed) note(s.face >= 0 ? s.face : face);
  }
  if (s.mode == State::kDone) return s.end_slot;
  if (s.mode != State::kFailed) note(s.face);  // out of faces
  return -1;
}

// Where a node lies: a face and barycentric coordinates in its (oriented) corner order.
Eigen::Vector3d Extractor::barycentric(const Node& n, int& face) const {
  face = n.face;
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  if (n.kind == Kind::kVertex) {
    b[corner_at(n.element, face)] = 1;
    return b;
  }
  auto coordinate = [](P2 p) { return Eigen::Vector2d(static_cast<double>(p.x), static_cast<double>(p.y)); };
  if (n.kind == Kind::kEdge) {
    const int ka = t_.corner_of(face, t_.edge_vertices(n.element, 0)), kb = t_.corner_of(face, t_.edge_vertices(n.element, 1));
    const Eigen::Vector2d a = coordinate(at(face, ka)), ab = coordinate(at(face, kb)) - a;
    const double lambda = std::clamp((coordinate(n.p) - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
    b[ka] = 1 - lambda, b[kb] = lambda;
    return b;
  }
  const Eigen::Vector2d a = coordinate(at(face, 0)), p = coordinate(n.p) - a;
  const Eigen::Vector2d e1 = coordinate(at(face, 1)) - a, e2 = coordinate(at(face, 2)) - a;
  const double det = e1.x() * e2.y() - e1.y() * e2.x();
  b[1] = (p.x() * e2.y() - p.y() * e2.x()) / det;
  b[2] = (e1.x() * p.y() - e1.y() * p.x()) / det;
  b[0] = 1 - b[1] - b[2];
  return b;
}

QuadMesh Extractor::run() {
  const auto t0 = linalg::Clock::now();
  const int nF = t_.num_faces, nE = t_.num_edges;
  if (param_.uv.rows() != 3 * nF || param_.uv.cols() != 2 || param_.rotation.size() != nE || param_.translation.rows() != nE)
    throw Error("quad: the map does not belong to this mesh (" + std::to_string(param_.uv.rows()) + " corner rows for " +
                std::to_string(nF) + " faces)");
  cut_.assign(nE, 0);
  for (int e : param_.cut_edges) {
    if (e < 0 || e >= nE || t_.is_boundary_edge(e))
      throw Error("quad: the map's cut edge " + std::to_string(e) + " is not an interior edge of this mesh");
    if (param_.rotation[e] < 0 || param_.rotation[e] > 3 || std::abs(param_.translation(e, 0)) >= kLargest ||
        std::abs(param_.translation(e, 1)) >= kLargest)
      throw Error("quad: the map's transition across edge " + std::to_string(e) + " (rotation " + std::to_string(param_.rotation[e]) +
                  ", translation " + std::to_string(param_.translation(e, 0)) + ", " + std::to_string(param_.translation(e, 1)) +
                  ") is not a quarter turn and a translation below 2^30");
    cut_[e] = 1;
  }
  build_fans();
  build_charts();
  join_points();
  find_points();
  const int nN = static_cast<int>(nodes_.size());
  q_.integer_points = nN;

  // Directions at every point.
  slot_offsets_.assign(nN + 1, 0);
  std::vector<Slot> local;
  for (int i = 0; i < nN; ++i) {
    slot_offsets_[i] = static_cast<int>(slots_.size());
    const Node& n = nodes_[i];
    if (n.kind == Kind::kVertex) {
      fan_slots(n.element, local);
    } else if (n.kind == Kind::kEdge) {
      edge_slots(n.element, local);
    } else {
      local = {{n.face, 0}, {n.face, 1}, {n.face, 2}, {n.face, 3}};
    }
    slots_.insert(slots_.end(), local.begin(), local.end());
    slot_node_.insert(slot_node_.end(), local.size(), i);
  }
  slot_offsets_[nN] = static_cast<int>(slots_.size());
  const int nS = static_cast<int>(slots_.size());

  // One trace per direction. A unit iso-line crosses a few faces where the mesh is finer than the quads; the
  // limit on all of them together is generous (16 per direction and face), reached only on wildly folded maps.
  step_budget_ = 16LL * (static_cast<long long>(nS) + nF) + 1000000;
  std::vector<int> target(nS, -1);
  for (int i = 0; i < nN; ++i)
    for (int s = slot_offsets_[i]; s < slot_offsets_[i + 1]; ++s) target[s] = trace(i, s);
  q_.traces = nS;
  for (int s = 0; s < nS; ++s) {
    if (target[s] < 0)
      ++q_.failed_traces;
    else if (target[target[s]] != s)
      ++q_.unmatched_traces;
  }

  // Faces: only the traces that come back (a trace and its twin) are edges; at every point the others are
  // skipped, so that turning is a permutation of the edges' sides and every walk closes. From each side, at its
  // end turn to the next edge clockwise of the way back. A walk that turns across the gap of a boundary point
  // (clockwise past its first direction) runs outside: a boundary loop.
  std::vector<char> kept(nS, 0);
  for (int s = 0; s < nS; ++s) kept[s] = target[s] >= 0 && target[target[s]] == s;
  std::vector<char> used(nS, 0);
  std::vector<std::vector<int>> faces;
  std::vector<int> walk;
  for (int s0 = 0; s0 < nS; ++s0) {
    if (used[s0] || !kept[s0]) continue;
    walk.clear();
    bool outside = false, closed = false;
    int s = s0;
    for (int step = 0; step < nS && !used[s]; ++step) {
      used[s] = 1;
      walk.push_back(slot_node_[s]);
      const int end = target[s], node = slot_node_[end];
      const int first = slot_offsets_[node], count = slot_offsets_[node + 1] - first;
      int j = end - first;
      do {
        if (j == 0 && nodes_[node].boundary) outside = true;
        j = (j + count - 1) % count;
      } while (!kept[first + j]);
      s = first + j;
      if (s == s0) {
        closed = true;
        break;
      }
    }
    if (!closed) {
      ++q_.open_faces;  // cannot happen on a permutation; counted rather than assumed
      continue;
    }
    if (outside) continue;
    faces.push_back(walk);
  }

  // Vertices: the points used by faces, in the order of the nodes.
  std::vector<int> index(nN, -1);
  for (const auto& face : faces)
    for (int node : face) index[node] = 0;
  int nQV = 0;
  for (int i = 0; i < nN; ++i)
    if (index[i] == 0) index[i] = nQV++;
  q_.unused_vertices = nN - nQV;
  QuadMesh out;
  out.V.resize(nQV, 3);
  out.vertex_face.resize(nQV);
  out.vertex_barycentric.resize(nQV, 3);
  out.vertex_cone = Eigen::VectorXi::Constant(nQV, -1);
  for (int i = 0; i < nN; ++i) {
    if (index[i] < 0) continue;
    const int j = index[i];
    int f = -1;
    const Eigen::Vector3d b = barycentric(nodes_[i], f);
    out.vertex_face[j] = f;
    out.vertex_barycentric.row(j) = b.transpose();
    out.V.row(j) = b[0] * V_.row(t_.F(f, 0)) + b[1] * V_.row(t_.F(f, 1)) + b[2] * V_.row(t_.F(f, 2));
    if (nodes_[i].kind == Kind::kVertex) out.vertex_cone[j] = nodes_[i].element;
  }
  int nQ = 0;
  for (const auto& face : faces) nQ += face.size() == 4;
  out.Q.resize(nQ, 4);
  nQ = 0;
  for (const auto& face : faces) {
    std::vector<int> ids;
    for (int node : face) ids.push_back(index[node]);
    if (ids.size() == 4) {
      out.Q.row(nQ++) << ids[0], ids[1], ids[2], ids[3];
    } else {
      out.other_faces.push_back(ids);
    }
  }
  q_.non_quad_faces = static_cast<int>(out.other_faces.size());
  const size_t first_sides = out.other_faces.empty() ? 0 : out.other_faces.front().size();
  if (options_.fill_faces && !out.other_faces.empty()) q_.filled_faces = quad::fill_faces(designer_, param_, out);
  q_.target_quads = param_.quality.target_squares;
  q_.map_folds = param_.quality.flipped_faces + param_.quality.degenerate_faces;
  q_.map_tiny_components = param_.quality.tiny_components;

  std::vector<std::string>& problems = q_.problems;
  auto say = [&](const std::string& s) { problems.push_back(s); };
  std::string where;  // said once, with the first sentence about dropped points or failed traces
  if (!q_.problem_faces.empty()) {
    std::ostringstream s;
    s << " (first at input faces";
    for (size_t i = 0; i < q_.problem_faces.size(); ++i) s << (i ? ", " : " ") << q_.problem_faces[i];
    s << ")";
    where = s.str();
  }
  auto located = [&](const std::string& s) {
    say(s + where);
    where.clear();
  };
  if (q_.unclosed_vertices > 0)
    say(std::to_string(q_.unclosed_vertices) +
        " input vertices do not get their (u, v) back around their fan through the map's transitions (the map is not seamless there)");
  if (q_.dropped_points > 0)
    located(std::to_string(q_.dropped_points) + " integer points lie inside folded or degenerate (u, v) triangles and were dropped");
  if (q_.failed_traces > 0)
    located(std::to_string(q_.failed_traces) + " of " + std::to_string(q_.traces) +
            " iso-line traces ended nowhere (they left the surface at an unaligned boundary, crossed a fold or ran out of faces)");
  if (q_.abandoned_traces > 0)
    say(std::to_string(q_.abandoned_traces) + " traces were abandoned: all traces together crossed more than " +
        std::to_string(step_budget_) + " faces (a wildly folded map)");
  if (q_.unmatched_traces > 0)
    say(std::to_string(q_.unmatched_traces) +
        " iso-line traces do not trace back to their start (a fold or a point missing at the other end)");
  if (q_.open_faces > 0) say(std::to_string(q_.open_faces) + " walks around faces of the traced graph did not close");
  if (q_.non_quad_faces > 0) {
    std::ostringstream s;
    s << q_.non_quad_faces << " faces of the traced graph are not quads (first with " << first_sides << " sides)";
    if (q_.filled_faces > 0) s << ": " << q_.filled_faces << " of them filled with quads (docs/quad.md, \"Faces\")";
    say(s.str());
  }
  q_.seconds_extract = linalg::seconds_since(t0);
  out.quality = q_;
  return out;
}

}  // namespace

QuadMesh extract_quads(const FieldDesigner& designer, const Parametrization& param, const QuadOptions& options) {
  Extractor extractor(designer, param, options);
  QuadMesh out = extractor.run();
  if (options.relax_below > 0) {
    const auto t0 = linalg::Clock::now();
    out.quality.relaxed_vertices = quad::relax_quads(designer, param, out, options.relax_below);
    out.quality.seconds_extract += linalg::seconds_since(t0);
  }
  if (options.check) check_quads(designer, param, out);
  return out;
}

}  // namespace trivcon
