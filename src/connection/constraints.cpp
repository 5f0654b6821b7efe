// SPDX-License-Identifier: MIT
#include "trivcon/constraints.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <unordered_set>
#include <vector>

#include "trivcon/error.h"
#include "trivcon/field.h"

namespace trivcon {

std::vector<FixedPath> fixed_face_paths(const Topology& t, const std::vector<int>& fixed, const std::vector<char>& usable) {
  const int nF = t.num_faces;
  std::vector<int> region(nF, -1), parent_edge(nF, -1), parent_face(nF, -1), depth(nF, 0);
  std::vector<int> queue;
  queue.reserve(nF);
  for (size_t i = 0; i < fixed.size(); ++i) {
    region[fixed[i]] = static_cast<int>(i);
    queue.push_back(fixed[i]);
  }
  // Multi-source breadth-first growth through usable edges; then, from everything reached, through the
  // unusable ones too, so that faces walled in by zero weights (and the fixed faces among them) still get a
  // region, and every fixed face of a component is linked to the others (a face cut off by zero weights
  // was left without a path before, and its direction was not held).
  for (int phase = 0; phase < 2; ++phase) {
    const size_t start = queue.size();
    if (phase == 1)
      for (size_t q = 0; q < start; ++q) queue.push_back(queue[q]);
    for (size_t q = phase == 0 ? 0 : start; q < queue.size(); ++q) {
      const int f = queue[q];
      for (int k = 0; k < 3; ++k) {
        const int e = t.face_edges(f, k);
        if (t.is_boundary_edge(e) || (phase == 0 && !usable[e])) continue;
        const int g = t.edge_faces(e, 0) == f ? t.edge_faces(e, 1) : t.edge_faces(e, 0);
        if (region[g] >= 0) continue;
        region[g] = region[f], parent_edge[g] = e, parent_face[g] = f, depth[g] = depth[f] + 1;
        queue.push_back(g);
      }
    }
  }
  // Links between regions: interior edges whose faces lie in different regions, shortest first.
  struct Link {
    int rigid, length, edge;  // rigid: across an unusable edge (only when nothing else links two regions)
  };
  std::vector<Link> links;
  for (int e = 0; e < t.num_edges; ++e) {
    if (t.is_boundary_edge(e)) continue;
    const int L = t.edge_faces(e, 0), R = t.edge_faces(e, 1);
    if (region[L] >= 0 && region[R] >= 0 && region[L] != region[R]) links.push_back({usable[e] ? 0 : 1, depth[L] + depth[R] + 1, e});
  }
  std::sort(links.begin(), links.end(),
            [](const Link& a, const Link& b) { return std::tie(a.rigid, a.length, a.edge) < std::tie(b.rigid, b.length, b.edge); });
  std::vector<int> set(fixed.size());
  std::iota(set.begin(), set.end(), 0);
  auto find = [&](int a) {
    while (set[a] != a) a = set[a] = set[set[a]];
    return a;
  };
  std::vector<FixedPath> paths;
  for (const Link& link : links) {
    const int e = link.edge, L = t.edge_faces(e, 0), R = t.edge_faces(e, 1);
    const int a = find(region[L]), b = find(region[R]);
    if (a == b) continue;
    set[std::max(a, b)] = std::min(a, b);
    FixedPath p;
    p.from_face = fixed[region[L]];
    p.to_face = fixed[region[R]];
    p.path.component = t.face_component[L];
    // From the fixed face down to L: collect L's ancestry, then walk it from the top.
    std::vector<int> up;
    for (int f = L; parent_face[f] >= 0; f = parent_face[f]) up.push_back(f);
    for (auto it = up.rbegin(); it != up.rend(); ++it) {
      const int edge = parent_edge[*it];
      p.path.edges.push_back(edge);
      p.path.signs.push_back(t.edge_faces(edge, 0) == parent_face[*it] ? 1 : -1);  // parent → child
    }
    p.path.edges.push_back(e);
    p.path.signs.push_back(1);  // L → R
    for (int f = R; parent_face[f] >= 0; f = parent_face[f]) {
      const int edge = parent_edge[f];
      p.path.edges.push_back(edge);
      p.path.signs.push_back(t.edge_faces(edge, 0) == f ? 1 : -1);  // child → parent
    }
    paths.push_back(std::move(p));
  }
  return paths;
}

std::map<int, double> boundary_alignment(const MatrixX3d& V, const Topology& t, const Geometry& g) {
  std::map<int, double> fixed;
  for (int f = 0; f < t.num_faces; ++f) {
    double longest = -1;
    for (int k = 0; k < 3; ++k) {
      const int e = t.face_edges(f, k);
      if (!t.is_boundary_edge(e) || zero_length_edge(V, t, e)) continue;  // no direction to follow
      // f's boundary half-edge runs corner k → k+1, the direction of its boundary loop.
      const double length = (V.row(t.F(f, (k + 1) % 3)) - V.row(t.F(f, k))).squaredNorm();
      if (length > longest) longest = length, fixed[f] = g.half_edge_angle(f, k);
    }
  }
  return fixed;
}

std::vector<FixedConflict> fixed_conflicts(const Topology& t, const Geometry& g, const std::map<int, double>& fixed, int N) {
  std::vector<FixedConflict> out;
  const double limit = kPi / (2 * N);
  for (int e = 0; e < t.num_edges; ++e) {
    if (t.is_boundary_edge(e)) continue;
    const int L = t.edge_faces(e, 0), R = t.edge_faces(e, 1);
    auto a = fixed.find(L), b = fixed.find(R);
    if (a == fixed.end() || b == fixed.end()) continue;
    const double turn = reduce_angle(b->second - a->second - g.rho(e), N);
    if (std::abs(turn) > limit) out.push_back({L, R, turn});
  }
  return out;
}

}  // namespace trivcon

namespace trivcon {

namespace {

// One step of a walk around a boundary vertex's fan: across interior edge `edge` from face `from` to `to`;
// `sign` is the step's coefficient in the vertex cycle (+1 where v is the edge's larger id and the walk goes
// from L to R, trivcon/cycles.h), so that the fan's part of a loop cycle sum is Σ sign · d_e.
struct FanStep {
  int edge, from, to;
  double sign;
};

// The fan of boundary vertex v, from the face of one of its boundary edges to the face of the other.
std::vector<FanStep> boundary_fan(const Topology& t, int v) {
  std::vector<FanStep> steps;
  int first_boundary = -1;
  for (int a = t.vertex_edge_offsets[v]; a < t.vertex_edge_offsets[v + 1] && first_boundary < 0; ++a)
    if (t.is_boundary_edge(t.vertex_edges[a])) first_boundary = t.vertex_edges[a];
  if (first_boundary < 0) return steps;
  int f = t.edge_faces(first_boundary, 0) >= 0 ? t.edge_faces(first_boundary, 0) : t.edge_faces(first_boundary, 1);
  int previous = first_boundary;
  steps.push_back({-1, -1, f, 0});  // the start face
  for (int count = 0; count <= t.num_faces; ++count) {
    int next = -1;
    for (int k = 0; k < 3; ++k) {
      const int e = t.face_edges(f, k);
      if (e != previous && (t.edge_vertices(e, 0) == v || t.edge_vertices(e, 1) == v)) next = e;
    }
    if (next < 0 || t.is_boundary_edge(next)) break;
    const bool from_left = t.edge_faces(next, 0) == f;
    const int h = from_left ? t.edge_faces(next, 1) : t.edge_faces(next, 0);
    steps.push_back({next, f, h, (t.edge_vertices(next, 1) == v ? 1.0 : -1.0) * (from_left ? 1.0 : -1.0)});
    previous = next, f = h;
  }
  return steps;
}

// β carried across a step by parallel transport (β_R = β_L + ρ_e, trivcon/field.h).
double carried(const Geometry& g, const FanStep& s, const Topology& t, double beta) {
  return t.edge_faces(s.edge, 0) == s.from ? beta + g.rho(s.edge) : beta - g.rho(s.edge);
}

// The closest reading of a fan whose end faces are fixed: the direction carried by parallel transport
// between fixed faces and turned onto each by the closest of the N choices. Returns false when an end is
// not fixed; `ambiguous` counts turns within 1e-6 of π/N.
bool closest_fan_turning(const Topology& t, const Geometry& g, const std::map<int, double>& fixed, int N, const std::vector<FanStep>& fan,
                         double& turning, int& ambiguous) {
  turning = 0, ambiguous = 0;
  if (fan.empty()) return true;
  const auto start = fixed.find(fan.front().to), end = fixed.find(fan.back().to);
  if (start == fixed.end() || end == fixed.end()) return false;
  double beta = start->second;
  for (size_t k = 1; k < fan.size(); ++k) {
    const double moved = carried(g, fan[k], t, beta);
    const auto target = fixed.find(fan[k].to);
    if (target == fixed.end()) {
      beta = moved;
      continue;
    }
    const double jump = reduce_angle(target->second - moved, N);
    if (std::abs(std::abs(jump) - kPi / N) < 1e-6) ++ambiguous;
    turning += fan[k].sign * jump;
    beta = target->second;
  }
  return true;
}

}  // namespace

std::vector<AlignedLoop> aligned_loop_indices(const Topology& t, const Geometry& g, const std::map<int, double>& fixed, int N) {
  std::vector<AlignedLoop> out;
  if (fixed.empty()) return out;
  const double period = 2 * kPi / N;
  for (size_t l = 0; l < t.boundary_loops.size(); ++l) {
    bool decided = true;
    double turning = 0;  // Σ over the loop's fans of the field's jumps relative to parallel transport
    int ambiguous = 0;
    for (int v : t.boundary_loops[l]) {
      double fan_turning = 0;
      int fan_ambiguous = 0;
      if (!closest_fan_turning(t, g, fixed, N, boundary_fan(t, v), fan_turning, fan_ambiguous)) {
        decided = false;
        break;
      }
      turning += fan_turning, ambiguous += fan_ambiguous;
    }
    if (!decided) continue;
    const double raw = (loop_curvature(t, g, static_cast<int>(l)) + turning) / period;
    const double rounded = std::round(raw);
    if (std::abs(raw - rounded) > 0.1) continue;  // not a consistent reading (degenerate geometry): decide nothing
    out.push_back({static_cast<int>(l), static_cast<int>(rounded), ambiguous});
  }
  return out;
}

namespace {

// The interior vertex nearest to v by edges (the smallest id among the nearest), or −1 when its component has none.
int nearest_interior_vertex(const Topology& t, int v) {
  std::vector<int> layer{v}, next;
  std::unordered_set<int> seen{v};
  while (!layer.empty()) {
    int best = -1;
    next.clear();
    for (int u : layer)
      for (int j = t.vertex_edge_offsets[u]; j < t.vertex_edge_offsets[u + 1]; ++j) {
        const int e = t.vertex_edges[j];
        const int w = t.edge_vertices(e, 0) == u ? t.edge_vertices(e, 1) : t.edge_vertices(e, 0);
        if (!seen.insert(w).second) continue;
        if (t.is_interior_vertex(w) && (best < 0 || w < best)) best = w;
        next.push_back(w);
      }
    if (best >= 0) return best;
    layer.swap(next);
  }
  return -1;
}

}  // namespace

std::map<int, int> boundary_turns_moved_inside(const Topology& t, const Geometry& g, const std::map<int, double>& fixed, const Field& field) {
  std::map<int, int> moved;
  if (fixed.empty()) return moved;
  const int N = field.N;
  const double period = 2 * kPi / N;
  for (int v = 0; v < t.num_vertices; ++v) {
    if (!t.is_boundary_vertex(v)) continue;
    const std::vector<FanStep> fan = boundary_fan(t, v);
    double closest = 0;
    int ambiguous = 0;
    if (fan.size() < 2 || !closest_fan_turning(t, g, fixed, N, fan, closest, ambiguous) || ambiguous > 0) continue;
    double read = 0;  // the field's own reading: each jump by the closest matching (field_indices)
    int inside = -1;
    for (size_t k = 1; k < fan.size(); ++k) {
      const FanStep& s = fan[k];
      read += s.sign * reduce_angle(field.angle(s.to) - carried(g, s, t, field.angle(s.from)), N);
      const int other = t.edge_vertices(s.edge, 0) == v ? t.edge_vertices(s.edge, 1) : t.edge_vertices(s.edge, 0);
      if (t.is_interior_vertex(other) && (inside < 0 || other < inside)) inside = other;
    }
    const int excess = static_cast<int>(std::lround((read - closest) / period));
    if (excess == 0) continue;
    // No interior neighbour (a strip one triangle wide, as a scan's holes leave): the nearest interior vertex by
    // edges, the smallest id among those as near; none in a component without interior vertices.
    if (inside < 0) inside = nearest_interior_vertex(t, v);
    if (inside < 0) continue;
    if ((moved[inside] += excess) == 0) moved.erase(inside);
  }
  return moved;
}

void check_aligned_index_sums(const Topology& t, const Geometry& g, const IndexPrescription& p) {
  if (p.fixed.empty() || t.boundary_loops.empty()) return;
  const std::vector<AlignedLoop> loops = aligned_loop_indices(t, g, p.fixed, p.N);
  std::vector<int> decided_loops(t.components.size(), 0), ambiguous(t.components.size(), 0);
  std::vector<long long> loop_sum(t.components.size(), 0), vertex_sum(t.components.size(), 0);
  for (const AlignedLoop& a : loops) {
    const int c = t.vertex_component[t.boundary_loops[a.loop].front()];
    ++decided_loops[c];
    loop_sum[c] += a.index;
    ambiguous[c] += a.ambiguous;
    const auto given = p.loop.find(a.loop);
    if (given != p.loop.end() && std::abs(given->second - a.index) > a.ambiguous)
      throw Error("boundary loop " + std::to_string(a.loop) + " is given index " + format_index(given->second, p.N) +
                  ", but the fixed directions along it (boundary alignment) turn with index " + format_index(a.index, p.N) +
                  ": the field would turn by 2pi/N or more across edges to reach them; give it " + format_index(a.index, p.N) +
                  " or leave it out");
  }
  for (auto [v, n] : p.vertex)
    if (v >= 0 && v < t.num_vertices && t.vertex_component[v] >= 0) vertex_sum[t.vertex_component[v]] += n;
  for (size_t c = 0; c < t.components.size(); ++c) {
    const ComponentInfo& info = t.components[c];
    if (info.boundary_loops.empty() || decided_loops[c] != static_cast<int>(info.boundary_loops.size())) continue;
    const long long needed = static_cast<long long>(p.N) * info.euler_characteristic - loop_sum[c];
    if (std::abs(needed - vertex_sum[c]) <= ambiguous[c]) continue;
    const long long missing = needed - vertex_sum[c];
    std::string hint;
    if (missing > 0 && missing <= 64 && p.N > 1)
      hint = " (e.g. " + std::to_string(missing) + " of +" + format_index(1, p.N) + ")";
    else if (missing < 0 && -missing <= 64 && p.N > 1)
      hint = " (e.g. " + std::to_string(-missing) + " of " + format_index(-1, p.N) + ")";
    throw Error("component " + std::to_string(c) + " (containing face " + std::to_string(info.first_face) +
                "): its fixed boundary directions (boundary alignment) need interior singularities summing to " +
                format_index(static_cast<int>(needed), p.N) + " (Gauss-Bonnet with the boundary's turning, Euler characteristic " +
                std::to_string(info.euler_characteristic) + "), but the prescription's sum to " +
                format_index(static_cast<int>(vertex_sum[c]), p.N) + "; place singularities summing to " +
                format_index(static_cast<int>(missing), p.N) + hint +
                ", or let trivcon place them (--auto; Python singularities=\"auto\"; the editor's auto button)");
  }
}

}  // namespace trivcon
