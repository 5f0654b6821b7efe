// SPDX-License-Identifier: MIT
#include "trivcon/features.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <sstream>

#include "trivcon/error.h"
#include "trivcon/field.h"
#include "field/edge_dijkstra.h"

namespace trivcon {

namespace {

// Corner k of face f such that the face's half-edge k → k+1 is edge e (in the oriented Topology::F).
int corner_of_edge(const Topology& t, int f, int e) {
  for (int k = 0; k < 3; ++k)
    if (t.face_edges(f, k) == e) return k;
  return -1;
}

// The sectors around vertex v between consecutive sharp edges, counter-clockwise: around an interior vertex none
// when fewer than two sharp edges meet there; with `boundary`, around a boundary vertex from its fan's first
// boundary edge to its last, cut at the sharp edges between (none without `boundary`). A face at v holds its
// corner k at v; its outgoing half-edge there is face_edges(f, k) (k → k+1), its incoming one face_edges(f, k+2);
// the next face counter-clockwise is across the incoming one.
struct Sector {
  int first = -1, second = -1;  // the sharp (or boundary) edges: the first face's outgoing, the last face's incoming half-edge
  std::vector<int> faces;
  double theta = 0;  // the corners' angles at v
};

std::vector<Sector> sectors_at(const Topology& t, const Geometry& g, int v, const std::vector<char>& sharp, bool boundary = false) {
  std::vector<Sector> out;
  Sector s;
  auto add = [&](int f, bool& closes) {
    const int k = t.corner_of(f, v);
    if (s.faces.empty()) s.first = t.face_edges(f, k);
    s.faces.push_back(f);
    s.theta += g.corner_angles(f, k);
    const int incoming = t.face_edges(f, (k + 2) % 3);
    closes = sharp[incoming] || t.is_boundary_edge(incoming);
    if (closes) {
      s.second = incoming;
      out.push_back(std::move(s));
      s = Sector();
    }
    return incoming;
  };
  bool closes = false;
  if (t.is_boundary_vertex(v)) {
    if (!boundary) return out;
    std::vector<int> fan;
    vertex_fan(t, v, fan);
    for (int f : fan) add(f, closes);
    if (!closes) out.clear();  // a fan that does not end on the boundary (not a manifold boundary vertex)
    return out;
  }
  if (!t.is_interior_vertex(v)) return out;
  int start = -1, count = 0;
  for (int j = t.vertex_face_offsets[v]; j < t.vertex_face_offsets[v + 1]; ++j) {
    const int f = t.vertex_faces[j];
    if (sharp[t.face_edges(f, t.corner_of(f, v))]) ++count, start = start < 0 ? f : start;
  }
  if (count < 2) return out;
  int f = start;
  for (int step = t.vertex_face_offsets[v + 1] - t.vertex_face_offsets[v]; step > 0; --step) {
    const int incoming = add(f, closes);
    f = t.edge_faces(incoming, 0) == f ? t.edge_faces(incoming, 1) : t.edge_faces(incoming, 0);
  }
  return out;
}

// The steps the field takes through a sector: one into each face and one out of the last, except at a boundary
// edge, whose face follows it exactly (no face lies across it).
int sector_steps(const Topology& t, const Sector& s) {
  return static_cast<int>(s.faces.size()) + 1 - t.is_boundary_edge(s.first) - t.is_boundary_edge(s.second);
}

// Whether the sector can be turned through with `steps` corners (steps · 2π/N) in steps the field reads
// unambiguously: at least one corner and one step, each step off its edges' directions by less than 0.9 π/N.
bool takes_steps(const Topology& t, const Sector& s, int steps, int N) {
  const int gaps = sector_steps(t, s);
  return steps >= 1 && gaps >= 1 && std::abs(s.theta - steps * 2 * kPi / N) / gaps < 0.9 * kPi / N;
}

// Whether a face of the sector lies beside a sharp edge other than the sector's two, or is taken already.
bool sector_is_plain(const Sector& s, const std::map<int, std::vector<int>>& sharp_beside, const std::vector<char>& claimed) {
  for (int w : s.faces) {
    if (claimed[w]) return false;
    const auto it = sharp_beside.find(w);
    if (it != sharp_beside.end())
      for (int e : it->second)
        if (e != s.first && e != s.second) return false;
  }
  return true;
}

// Fixes the sector's faces W_1..W_m to the first edge's direction turned by δ = (θ − steps·2π/N)/(sector_steps)
// at each step: with the faces across the two edges (which follow them), or the edges themselves where they are
// boundary edges, the field turns through the sector by θ − steps·2π/N, so a map gives the sector steps·2π/N.
void turn_through(const Topology& t, const Geometry& g, int v, const Sector& s, int steps, int N, std::map<int, double>& fixed,
                  std::vector<char>& claimed) {
  const int m = static_cast<int>(s.faces.size()), before = t.is_boundary_edge(s.first) ? 0 : 1;
  const double delta = (s.theta - steps * 2 * kPi / N) / sector_steps(t, s);
  double gamma = 0;  // the angle at v from the first edge to W_i's outgoing half-edge
  for (int i = 0; i < m; ++i) {
    const int w = s.faces[i], c = t.corner_of(w, v);
    fixed[w] = wrap_angle(g.half_edge_angle(w, c) - gamma + (i + before) * delta);
    claimed[w] = 1;
    gamma += g.corner_angles(w, c);
  }
}

std::vector<char> sharp_flags(const Topology& t, const std::vector<int>& edges) {
  std::vector<char> sharp(t.num_edges, 0);
  for (int e : edges) sharp[e] = 1;
  return sharp;
}

std::map<int, std::vector<int>> sharp_faces(const Topology& t, const std::vector<int>& edges) {
  std::map<int, std::vector<int>> out;
  for (int e : edges)
    for (int side = 0; side < 2; ++side)
      if (t.edge_faces(e, side) >= 0) out[t.edge_faces(e, side)].push_back(e);
  return out;
}

// The boundary edges, as lines beside their faces (with `boundary`, the aligned boundary is a line too).
std::vector<int> boundary_edges_beside(const Topology& t, std::map<int, std::vector<int>>& beside) {
  std::vector<int> out;
  for (int e = 0; e < t.num_edges; ++e)
    if (t.is_boundary_edge(e)) out.push_back(e), beside[t.edge_faces(e, 0) >= 0 ? t.edge_faces(e, 0) : t.edge_faces(e, 1)].push_back(e);
  return out;
}

// Narrow corners (trivcon/features.h): sectors of angle θ < π/N between consecutive sharp edges. Following
// both edges the field would turn by θ through the sector and a map aligned to both would collapse it; turned
// through with one step (turn_through), it gets a corner of 2π/N.
void narrow_corners(const Topology& t, const Geometry& g, const std::vector<int>& edges, int N, FeatureAlignment& out) {
  if (N < 4 || N % 2 != 0) return;  // a sense-free step of 2π/N that a quad or hexagon corner can take
  const std::vector<char> sharp = sharp_flags(t, edges);
  const std::map<int, std::vector<int>> beside = sharp_faces(t, edges);
  std::vector<char> claimed(t.num_faces, 0), seen(t.num_vertices, 0);
  for (int e : edges)
    for (int end = 0; end < 2; ++end) {
      const int v = t.edge_vertices(e, end);
      if (seen[v]) continue;
      seen[v] = 1;
      for (const Sector& s : sectors_at(t, g, v, sharp))
        if (s.theta < kPi / N && sector_is_plain(s, beside, claimed)) {
          turn_through(t, g, v, s, 1, N, out.fixed, claimed);
          out.narrow.push_back({v, s.first, s.second, s.theta, s.faces});
        }
    }
  std::sort(out.narrow.begin(), out.narrow.end(), [](const NarrowCorner& a, const NarrowCorner& b) { return a.vertex < b.vertex; });
  if (out.narrow.empty()) return;
  // A face of a narrow corner follows neither edge on purpose: it is no conflict.
  out.conflicts.erase(std::remove_if(out.conflicts.begin(), out.conflicts.end(), [&](const FeatureConflict& k) { return claimed[k.face]; }),
                      out.conflicts.end());
}

}  // namespace

double dihedral_angle(const Topology& t, const Geometry& g, int e) {
  if (t.is_boundary_edge(e)) return 0;
  const Eigen::Vector3d nL = g.normal.row(t.edge_faces(e, 0)), nR = g.normal.row(t.edge_faces(e, 1));
  return std::atan2(nL.cross(nR).norm(), nL.dot(nR));
}

bool is_convex_edge(const MatrixX3d& V, const Topology& t, const Geometry& g, int e) {
  if (t.is_boundary_edge(e)) return false;
  const Eigen::Vector3d nL = g.normal.row(t.edge_faces(e, 0)), nR = g.normal.row(t.edge_faces(e, 1));
  const Eigen::Vector3d d = V.row(t.edge_vertices(e, 1)) - V.row(t.edge_vertices(e, 0));
  return nL.cross(nR).dot(d) > 0;
}

std::vector<int> sharp_edges(const MatrixX3d& V, const Topology& t, const Geometry& g, double degrees) {
  (void)V;  // the normals come from the geometry; V is taken as by the other feature functions
  if (!(degrees >= 0 && degrees <= 180)) {
    std::ostringstream s;
    s << degrees;
    throw Error("feature angle " + s.str() + " out of range: expected degrees in [0, 180]");
  }
  const double limit = degrees * kPi / 180;
  std::vector<int> out;
  for (int e = 0; e < t.num_edges; ++e)
    if (!t.is_boundary_edge(e) && dihedral_angle(t, g, e) > limit) out.push_back(e);
  return out;
}

namespace {

// A mask of `edges` (edge ids; `what` names the caller in the error for one out of range).
std::vector<char> edge_mask(const Topology& t, const std::vector<int>& edges, const char* what) {
  std::vector<char> alive(t.num_edges, 0);
  for (int e : edges) {
    if (e < 0 || e >= t.num_edges) throw Error(std::string(what) + ": edge " + std::to_string(e) + " out of range");
    alive[e] = 1;
  }
  return alive;
}

// `edges` still in the mask, in their order; the others to `dropped` when given.
std::vector<int> kept_edges(const std::vector<int>& edges, const std::vector<char>& alive, std::vector<int>* dropped) {
  std::vector<int> kept;
  for (int e : edges) {
    if (alive[e]) kept.push_back(e);
    else if (dropped) dropped->push_back(e);
  }
  return kept;
}

}  // namespace

std::vector<int> without_short_feature_ends(const MatrixX3d& V, const Topology& t, const std::vector<int>& edges, double min_length,
                                            std::vector<int>* dropped) {
  std::vector<char> alive = edge_mask(t, edges, "without_short_feature_ends");
  auto other_end = [&](int e, int v) { return t.edge_vertices(e, 0) == v ? t.edge_vertices(e, 1) : t.edge_vertices(e, 0); };
  auto sharp_at = [&](int v) {
    std::vector<int> out;
    for (int q = t.vertex_edge_offsets[v]; q < t.vertex_edge_offsets[v + 1]; ++q)
      if (alive[t.vertex_edges[q]]) out.push_back(t.vertex_edges[q]);
    return out;
  };
  std::vector<int> ends;  // vertices of the edges: where chains may have free ends
  for (int e : edges) ends.push_back(t.edge_vertices(e, 0)), ends.push_back(t.edge_vertices(e, 1));
  std::sort(ends.begin(), ends.end());
  ends.erase(std::unique(ends.begin(), ends.end()), ends.end());
  for (bool changed = min_length > 0; changed;) {
    changed = false;
    std::vector<int> drop;
    for (int v : ends) {
      std::vector<int> at = sharp_at(v);
      if (at.size() != 1) continue;
      // Walk the chain from its free end to the next vertex where other than two sharp edges meet.
      std::vector<int> chain;
      double length = 0;
      int e = at[0], w = v;
      while (true) {
        chain.push_back(e);
        const int next = other_end(e, w);
        length += (V.row(next) - V.row(w)).norm();
        at = sharp_at(next);
        if (at.size() != 2 || length >= min_length) break;
        e = at[0] == e ? at[1] : at[0], w = next;
      }
      if (length < min_length) drop.insert(drop.end(), chain.begin(), chain.end());
    }
    for (int e : drop) changed |= alive[e] != 0, alive[e] = 0;
  }
  // Then every connected piece less than min_length across (the largest distance between two of its vertices):
  // a small closed network of creases, as where a scan's noise rings a rounded tip. The distance from one vertex
  // to the farthest, d, bounds it (d ≤ across ≤ 2d); pairs are compared only between those bounds.
  std::vector<char> seen(t.num_vertices, 0);
  for (int v : ends) {
    if (seen[v] || min_length <= 0 || sharp_at(v).empty()) continue;
    std::vector<int> piece{v}, piece_edges;
    seen[v] = 1;
    for (size_t k = 0; k < piece.size(); ++k)
      for (int e : sharp_at(piece[k])) {
        const int w = other_end(e, piece[k]);
        if (t.edge_vertices(e, 0) == piece[k]) piece_edges.push_back(e);  // each edge once, from its first end
        if (!seen[w]) seen[w] = 1, piece.push_back(w);
      }
    double from_first = 0;
    for (int w : piece) from_first = std::max(from_first, (V.row(w) - V.row(v)).norm());
    double across = from_first;
    if (from_first < min_length && 2 * from_first >= min_length)
      for (size_t a = 0; a < piece.size() && across < min_length; ++a)
        for (size_t b = a + 1; b < piece.size(); ++b) across = std::max(across, (V.row(piece[a]) - V.row(piece[b])).norm());
    if (across < min_length)
      for (int e : piece_edges) alive[e] = 0;
  }
  return kept_edges(edges, alive, dropped);
}

std::vector<int> without_closed_faces(const Topology& t, const Geometry& g, const std::vector<int>& edges, std::vector<int>* dropped) {
  std::vector<char> alive = edge_mask(t, edges, "without_closed_faces");
  for (int f = 0; f < t.num_faces; ++f) {
    if (!(alive[t.face_edges(f, 0)] && alive[t.face_edges(f, 1)] && alive[t.face_edges(f, 2)])) continue;
    int least = t.face_edges(f, 0);
    for (int k = 1; k < 3; ++k) {
      const int e = t.face_edges(f, k);
      const double a = dihedral_angle(t, g, e), b = dihedral_angle(t, g, least);
      if (a < b || (a == b && e > least)) least = e;
    }
    alive[least] = 0;
  }
  return kept_edges(edges, alive, dropped);
}

FeatureAlignment feature_alignment(const MatrixX3d& V, const Topology& t, const Geometry& g, const std::vector<int>& edges, int N) {
  if (N < 1) throw Error("feature_alignment: N = " + std::to_string(N) + " (need N >= 1)");
  // Per face, its feature edges with their direction (p_j − p_i, i < j, in the face's frame) and length.
  struct Candidate {
    int edge;
    double angle, length;
  };
  std::map<int, std::vector<Candidate>> beside;
  for (int e : edges) {
    if (e < 0 || e >= t.num_edges || t.is_boundary_edge(e))
      throw Error("feature_alignment: edge " + std::to_string(e) + " is not an interior edge of the mesh");
    const double length = (V.row(t.edge_vertices(e, 1)) - V.row(t.edge_vertices(e, 0))).norm();
    for (int side = 0; side < 2; ++side) {
      const int f = t.edge_faces(e, side);
      // L holds i → j, R holds j → i: R's half-edge is turned by π to give the same sense.
      const double angle = wrap_angle(g.half_edge_angle(f, corner_of_edge(t, f, e)) + (side == 1 ? kPi : 0.0));
      beside[f].push_back({e, angle, length});
    }
  }
  FeatureAlignment out;
  for (auto& [f, list] : beside) {
    // The longest edge is followed; ties go to the smaller edge id, so the choice is deterministic.
    std::sort(list.begin(), list.end(),
              [](const Candidate& a, const Candidate& b) { return a.length != b.length ? a.length > b.length : a.edge < b.edge; });
    out.fixed[f] = list[0].angle;
    if (list.size() > 1) ++out.corner_faces;
    for (size_t k = 1; k < list.size(); ++k) {
      const double difference = std::abs(reduce_angle(list[k].angle - list[0].angle, N));
      if (difference > kFeatureAngleTolerance) out.conflicts.push_back({f, list[0].edge, list[k].edge, difference});
    }
  }
  narrow_corners(t, g, edges, N, out);
  return out;
}

void move_singularities_onto_features(const MatrixX3d& V, const Topology& t, const Geometry& g, const std::vector<int>& edges, int N,
                                      double distance, bool flat_sectors, std::map<int, int>& vertex, FeatureAlignment& alignment,
                                      double separation, bool boundary) {
  if (N < 4 || N % 2 != 0 || (edges.empty() && !boundary) || !(distance > 0)) return;
  const std::vector<char> sharp = sharp_flags(t, edges);
  std::map<int, std::vector<int>> beside = sharp_faces(t, edges);
  std::vector<int> degree(t.num_vertices, 0);
  for (int e : edges) ++degree[t.edge_vertices(e, 0)], ++degree[t.edge_vertices(e, 1)];
  if (boundary)
    for (int e : boundary_edges_beside(t, beside)) ++degree[t.edge_vertices(e, 0)], ++degree[t.edge_vertices(e, 1)];
  // Boundary vertices given a corner by this call's moves: no singularity there, but taken (an earlier call's are
  // in claimed sectors).
  std::set<int> corners;
  std::vector<char> claimed(t.num_faces, 0);
  for (const NarrowCorner& k : alignment.narrow)
    for (int f : k.faces) claimed[f] = 1;
  for (const FeatureSnap& k : alignment.snapped)  // turned by an earlier call
    for (int f : k.faces) claimed[f] = 1;
  std::vector<double> dist(t.num_vertices, std::numeric_limits<double>::infinity());
  // Whether a singularity other than s lies closer than `separation` to w.
  auto crowded = [&](int w, int s) {
    bool found = false;
    if (separation > 0)
      field::edge_dijkstra(V, t, w, separation, false, dist, [&](int v, double) {
        found = found || (v != s && (vertex.count(v) || corners.count(v)));
        return !found;
      });
    return found;
  };
  const std::map<int, int> given = vertex;
  for (auto [s, n] : given) {
    if (std::abs(n) != 1 || degree[s] > 0 || !t.is_interior_vertex(s)) continue;
    // The feature vertices nearest s, reached without passing another one: on the border of s's patch.
    std::map<int, double> reached;  // every vertex reached → its distance
    std::vector<std::pair<double, int>> candidates;
    field::edge_dijkstra(V, t, s, distance, false, dist, [&](int v, double d) {
      reached[v] = d;
      if (degree[v] == 0) return true;
      candidates.emplace_back(d, v);
      return false;
    });
    std::sort(candidates.begin(), candidates.end());
    for (auto [d, w] : candidates) {
      // A line vertex (two sharp edges) or a junction (more): either way its sector facing s lies between two.
      if (degree[w] < 2 || vertex.count(w) || corners.count(w) || crowded(w, s)) continue;
      // The sector of w facing s: the one holding the reached neighbour of w nearest s.
      int x = -1;
      double best = std::numeric_limits<double>::infinity();
      for (int j = t.vertex_edge_offsets[w]; j < t.vertex_edge_offsets[w + 1]; ++j) {
        const int e = t.vertex_edges[j];
        const int y = t.edge_vertices(e, 0) == w ? t.edge_vertices(e, 1) : t.edge_vertices(e, 0);
        const auto it = reached.find(y);
        if (!sharp[e] && it != reached.end() && degree[y] == 0 && it->second < best) best = it->second, x = y;
      }
      if (x < 0) continue;
      const std::vector<Sector> sectors = sectors_at(t, g, w, sharp, boundary);
      bool moved = false;
      for (const Sector& sector : sectors) {
        bool holds = false;
        for (int f : sector.faces)
          for (int k = 0; k < 3; ++k) holds = holds || t.F(f, k) == x;
        if (!holds) continue;
        const double step = 2 * kPi / N;
        const int steps = static_cast<int>(std::lround(sector.theta / step)) - n;  // one more for −1/N, one fewer for +1/N
        // The quad mesh gives the sector `steps` corners at w: wider than 1.5 steps each (a +1/N on a straight
        // line or on a T-junction's straight side: one corner of about π), they would be flat or reflex.
        const bool flat = sector.theta > 1.5 * steps * step;
        if (!takes_steps(t, sector, steps, N) || (flat && !flat_sectors) || !sector_is_plain(sector, beside, claimed)) break;
        turn_through(t, g, w, sector, steps, N, alignment.fixed, claimed);
        vertex.erase(s);
        if (t.is_boundary_vertex(w)) corners.insert(w), alignment.corners[w] = n;  // a corner of the boundary: no index
        else vertex[w] = n;
        alignment.snapped.push_back({s, w, d, sector.faces});
        moved = true;
        break;
      }
      // The nearest eligible candidate only, moved or not; on the boundary the next ones too: a fan of three
      // faces cannot turn a quarter in steps the field reads unambiguously (two of π/4), a wider one beside it can.
      if (moved || !t.is_boundary_vertex(w)) break;
    }
  }
}

std::map<int, int> with_corners(std::map<int, int> vertex, const std::map<int, int>& corners) {
  vertex.insert(corners.begin(), corners.end());
  return vertex;
}

void turn_sectors_for_singularities(const Topology& t, const Geometry& g, const std::vector<int>& edges, int N, const std::map<int, int>& vertex,
                                    FeatureAlignment& alignment, bool boundary) {
  if (N < 4 || N % 2 != 0 || (edges.empty() && !boundary)) return;
  const std::vector<char> sharp = sharp_flags(t, edges);
  const std::map<int, std::vector<int>> beside = sharp_faces(t, edges);
  // At a boundary vertex the boundary edges are lines too: a sector with a face beside another one is not plain.
  std::map<int, std::vector<int>> beside_boundary = beside;
  if (boundary) boundary_edges_beside(t, beside_boundary);
  std::vector<char> claimed(t.num_faces, 0);
  std::set<int> narrow_faces;
  for (const NarrowCorner& k : alignment.narrow)
    for (int f : k.faces) claimed[f] = 1, narrow_faces.insert(f);
  for (const auto* list : {&alignment.snapped, &alignment.given_sectors})
    for (const FeatureSnap& k : *list)
      for (int f : k.faces) claimed[f] = 1;
  const double step = 2 * kPi / N;
  for (auto [w, n] : vertex) {
    if (w < 0 || w >= t.num_vertices) continue;
    const bool corner = t.is_boundary_vertex(w);
    if (corner && (!boundary || alignment.corners.count(w))) continue;
    std::vector<Sector> sectors = sectors_at(t, g, w, sharp, corner);
    if (sectors.empty()) continue;
    // The sectors' whole steps as the alignment turns them now (a narrow corner's one, a sector turned by a
    // move onto the line one off its nearest: such a vertex holds its singularity already).
    bool turned = false;
    int sum = 0;
    for (const Sector& sector : sectors) {
      const bool narrow = narrow_faces.count(sector.faces.front()) > 0;
      turned = turned || (!narrow && claimed[sector.faces.front()]);
      sum += narrow ? 1 : static_cast<int>(std::lround(sector.theta / step));
    }
    if (turned) continue;
    // +: fewer steps wanted, −: more. An interior vertex reads N − Σk; a boundary vertex no index, so all n.
    int difference = corner ? n : n - (N - sum);
    while (difference != 0) {
      const int change = difference > 0 ? -1 : 1;
      const Sector* best = nullptr;
      int best_steps = 0;
      double best_misfit = 0;
      bool best_flat = true;
      for (const Sector& sector : sectors) {
        if (!sector_is_plain(sector, corner ? beside_boundary : beside, claimed)) continue;
        const int steps = static_cast<int>(std::lround(sector.theta / step)) + change;
        const double misfit = std::abs(sector.theta - steps * step);
        if (!takes_steps(t, sector, steps, N)) continue;
        const bool flat = sector.theta > 1.5 * steps * step;
        if (!best || (flat != best_flat ? !flat : misfit < best_misfit))
          best = &sector, best_steps = steps, best_misfit = misfit, best_flat = flat;
      }
      if (!best) break;
      turn_through(t, g, w, *best, best_steps, N, alignment.fixed, claimed);
      alignment.given_sectors.push_back({w, w, 0.0, best->faces});
      difference += change;
    }
    if (corner && difference == 0) alignment.corners[w] = n;
  }
}

}  // namespace trivcon
