// SPDX-License-Identifier: MIT
// Connectivity and validation in (near) linear time: half-edges are bucketed by their smaller vertex
// (counting sort), so matching the two sides of an edge costs O(degree) per vertex. Above 50k faces the
// independent passes (non-manifold vertices and orientation; the vertex-face and vertex-edge lists) run
// on two threads.
#include "trivcon/topology.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <exception>
#include <sstream>

#include "linalg/parallel.h"
#include "trivcon/error.h"

namespace trivcon {
namespace {

using linalg::kParallelMinElements;
using linalg::threads_for;

// Union-find with path halving; used for face fans around vertices.
struct DisjointSets {
  std::vector<int> parent;
  explicit DisjointSets(int n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  int find(int a) {
    while (parent[a] != a) a = parent[a] = parent[parent[a]];
    return a;
  }
  void unite(int a, int b) {
    a = find(a), b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
};

std::string face_string(const MatrixX3i& F, int f) {
  std::ostringstream s;
  s << "(" << F(f, 0) << ", " << F(f, 1) << ", " << F(f, 2) << ")";
  return s.str();
}

void check_face_indices(const MatrixX3i& F, int num_vertices) {
  for (int f = 0; f < F.rows(); ++f) {
    for (int k = 0; k < 3; ++k) {
      if (F(f, k) < 0 || F(f, k) >= num_vertices)
        throw Error("vertex index " + std::to_string(F(f, k)) + " out of range in face " + std::to_string(f) + " (mesh has " +
                    std::to_string(num_vertices) + " vertices)");
    }
    if (F(f, 0) == F(f, 1) || F(f, 1) == F(f, 2) || F(f, 2) == F(f, 0))
      throw Error("face " + std::to_string(f) + " has a repeated vertex " + face_string(F, f));
  }
}

// Groups the 3F half-edges (h = 3f + k, from corner k to k+1) into undirected edges. Returns the edge
// id of every half-edge; edges are numbered in order of first appearance. Linear time whatever the
// valences: one counting sort buckets the half-edges by their smaller vertex (in increasing h), then
// each bucket is sorted stably by the larger vertex (insertion sort: buckets hold about six entries; a
// merge sort for the rare large ones), so the half-edges of one edge become neighbours, smallest h first.
std::vector<int> match_half_edges(const MatrixX3i& F, int num_vertices, int& num_edges) {
  const int nF = static_cast<int>(F.rows()), H = 3 * nF;
  std::vector<int> offset(static_cast<size_t>(num_vertices) + 1, 0);
  for (int k = 0; k < 3; ++k)
    for (int f = 0; f < nF; ++f) ++offset[std::min(F(f, k), F(f, (k + 1) % 3)) + 1];
  std::partial_sum(offset.begin(), offset.end(), offset.begin());
  std::vector<std::pair<int, int>> bucket(H);  // (larger vertex, h), by smaller vertex
  {
    std::vector<int> fill(offset.begin(), offset.end() - 1);
    for (int f = 0; f < nF; ++f)
      for (int k = 0; k < 3; ++k) {
        const int a = F(f, k), b = F(f, (k + 1) % 3);
        bucket[fill[std::min(a, b)]++] = {std::max(a, b), 3 * f + k};
      }
  }
  std::vector<int> first_of(H);  // the first half-edge (smallest h) of h's edge
  for (int v = 0; v < num_vertices; ++v) {
    const auto begin = bucket.begin() + offset[v], end = bucket.begin() + offset[v + 1];
    if (end - begin > 32) {
      std::stable_sort(begin, end, [](const auto& x, const auto& y) { return x.first < y.first; });
    } else {
      for (auto i = begin + 1; i < end; ++i)
        for (auto j = i; j > begin && (j - 1)->first > j->first; --j) std::iter_swap(j - 1, j);
    }
    for (auto i = begin; i < end; ++i)
      first_of[i->second] = i > begin && (i - 1)->first == i->first ? first_of[(i - 1)->second] : i->second;
  }
  std::vector<int> edge_of(H);
  num_edges = 0;
  for (int h = 0; h < H; ++h) edge_of[h] = first_of[h] == h ? num_edges++ : edge_of[first_of[h]];
  return edge_of;
}

// Non-manifold vertices: corners (f, k) at the same vertex are joined across every edge with two faces;
// a manifold vertex has one group (one fan).
void check_manifold_vertices(const MatrixX3i& F_in, int num_vertices, const std::vector<int>& edge_count,
                             const std::vector<std::array<int, 2>>& edge_half) {
  const int H = 3 * static_cast<int>(F_in.rows()), nE = static_cast<int>(edge_count.size());
  DisjointSets corners(H);
  for (int e = 0; e < nE; ++e) {
    if (edge_count[e] != 2) continue;
    const int h0 = edge_half[e][0], h1 = edge_half[e][1];
    const int f0 = h0 / 3, f1 = h1 / 3;
    for (int end = 0; end < 2; ++end) {
      const int v = end == 0 ? F_in(f0, h0 % 3) : F_in(f0, (h0 % 3 + 1) % 3);
      int c1 = -1;
      for (int k = 0; k < 3; ++k)
        if (F_in(f1, k) == v) c1 = 3 * f1 + k;
      int c0 = end == 0 ? h0 : 3 * f0 + (h0 % 3 + 1) % 3;
      corners.unite(c0, c1);
    }
  }
  std::vector<int> fans(num_vertices, 0);
  for (int c = 0; c < H; ++c)
    if (corners.find(c) == c) ++fans[F_in(c / 3, c % 3)];
  for (int v = 0; v < num_vertices; ++v)
    if (fans[v] > 1)
      throw Error("non-manifold vertex " + std::to_string(v) + ": its faces form " + std::to_string(fans[v]) + " separate fans");
}

// The cycle of faces, each sharing an edge with the next, closed by the clash between f and g: along it the
// orientation must flip once. The paths from f and g up the breadth-first tree to their common ancestor.
std::string orientation_cycle(const std::vector<int>& reached_from, int f, int g) {
  std::vector<int> up_f{f}, up_g{g};
  while (reached_from[up_f.back()] >= 0) up_f.push_back(reached_from[up_f.back()]);
  while (reached_from[up_g.back()] >= 0) up_g.push_back(reached_from[up_g.back()]);
  while (up_f.size() > 1 && up_g.size() > 1 && up_f[up_f.size() - 2] == up_g[up_g.size() - 2]) up_f.pop_back(), up_g.pop_back();
  std::vector<int> cycle(up_g.begin(), up_g.end());        // g ... ancestor
  cycle.insert(cycle.end(), up_f.rbegin() + 1, up_f.rend());  // ... f
  cycle.push_back(g);
  std::string text = "the orientation flips once along the cycle of faces ";
  const size_t shown = cycle.size() <= 24 ? cycle.size() : 20;
  for (size_t i = 0; i < shown; ++i) text += (i ? " -> " : "") + std::to_string(cycle[i]);
  if (shown < cycle.size()) text += " -> ... -> " + std::to_string(cycle.back());
  return text + " (" + std::to_string(cycle.size() - 1) + " faces, each sharing an edge with the next)";
}


// Components and orientation: breadth-first over faces; flip[g] says whether g must be reversed to agree
// with its component's first face (the majority's orientation is kept). Fills t.face_component and
// t.components (one per connected set of faces, first_face set).
void orient_components(const MatrixX3i& F_in, const std::vector<int>& edge_count, const std::vector<std::array<int, 2>>& edge_half,
                       Topology& t, std::vector<char>& flip) {
  const int nF = static_cast<int>(F_in.rows()), H = 3 * nF, nE = static_cast<int>(edge_count.size());
  // twin[h] = 2 h' + s for the other half-edge h' of h's edge, s = 1 when both run the same way (one of
  // the two faces must flip); −1 on the boundary. Built once so that the search reads it in sequence.
  std::vector<int> twin(H, -1);
  for (int e = 0; e < nE; ++e) {
    if (edge_count[e] != 2) continue;
    const int h0 = edge_half[e][0], h1 = edge_half[e][1];
    const int same = F_in(h0 / 3, h0 % 3) == F_in(h1 / 3, h1 % 3);
    twin[h0] = 2 * h1 + same, twin[h1] = 2 * h0 + same;
  }
  t.face_component.assign(nF, -1);
  std::vector<int> queue;
  queue.reserve(nF);
  std::vector<int> reached_from(nF, -1);  // the breadth-first tree of faces (for the message of a clash)
  for (int root = 0; root < nF; ++root) {
    if (t.face_component[root] >= 0) continue;
    const int c = static_cast<int>(t.components.size());
    t.components.emplace_back();
    t.components.back().first_face = root;
    const size_t begin = queue.size();
    queue.push_back(root);
    t.face_component[root] = c;
    for (size_t q = begin; q < queue.size(); ++q) {
      const int f = queue[q];
      for (int k = 0; k < 3; ++k) {
        const int code = twin[3 * f + k];
        if (code < 0) continue;
        const int g = (code >> 1) / 3;
        const char want = flip[f] ^ static_cast<char>(code & 1);
        if (t.face_component[g] < 0) {
          t.face_component[g] = c;
          flip[g] = want;
          reached_from[g] = f;
          queue.push_back(g);
        } else if (flip[g] != want) {
          const int a = F_in(f, k), b = F_in(f, (k + 1) % 3);
          throw Error("non-orientable component " + std::to_string(c) + " (containing face " + std::to_string(root) + "): faces " +
                      std::to_string(std::min(f, g)) + " and " + std::to_string(std::max(f, g)) +
                      " cannot be oriented consistently across edge (" + std::to_string(std::min(a, b)) + ", " +
                      std::to_string(std::max(a, b)) + "); " + orientation_cycle(reached_from, f, g));
        }
      }
    }
    // Keep the orientation of the majority (ties: the first face's).
    size_t flipped = 0;
    for (size_t q = begin; q < queue.size(); ++q) flipped += flip[queue[q]];
    if (2 * flipped > queue.size() - begin)
      for (size_t q = begin; q < queue.size(); ++q) flip[queue[q]] ^= 1;
  }
}

}  // namespace

void check_finite(const MatrixX3d& V) {
  for (int v = 0; v < V.rows(); ++v)
    for (int k = 0; k < 3; ++k)
      if (!std::isfinite(V(v, k))) throw Error("non-finite coordinate in vertex " + std::to_string(v));
}

void check_coordinate_range(const MatrixX3d& V, const Topology& t) {
  constexpr double kLargest = 1e150, kSmallest = 1e-150;
  for (int v = 0; v < V.rows(); ++v)
    for (int k = 0; k < 3; ++k)
      if (std::abs(V(v, k)) > kLargest) {
        std::ostringstream message;
        message << "vertex " << v << " has coordinate " << V(v, k)
                << " beyond +-1e150: squared lengths would overflow; scale the mesh down (angles and fields do not depend on its size)";
        throw Error(message.str());
      }
  double longest = 0;
  int longest_edge = -1;
  for (int e = 0; e < t.num_edges; ++e) {
    const double l = (V.row(t.edge_vertices(e, 1)) - V.row(t.edge_vertices(e, 0))).cwiseAbs().maxCoeff();
    if (l > longest) longest = l, longest_edge = e;
  }
  if (t.num_edges > 0 && longest < kSmallest) {
    std::ostringstream message;
    message << "the mesh is too small: its longest edge";
    if (longest_edge >= 0) message << " (" << t.edge_vertices(longest_edge, 0) << ", " << t.edge_vertices(longest_edge, 1) << ")";
    message << " spans " << longest
            << ", below 1e-150, where squared lengths underflow; scale the mesh up (angles and fields do not depend on its size)";
    throw Error(message.str());
  }
}

int Topology::euler_characteristic() const {
  int chi = 0;
  for (const auto& c : components) chi += c.euler_characteristic;
  return chi;
}

Topology build_topology(const MatrixX3i& F_in, int num_vertices) {
  check_face_indices(F_in, num_vertices);
  Topology t;
  t.num_vertices = num_vertices;
  t.num_faces = static_cast<int>(F_in.rows());
  const int nF = t.num_faces, H = 3 * nF;
  std::vector<int> edge_of = match_half_edges(F_in, num_vertices, t.num_edges);
  const int nE = t.num_edges;

  // Half-edges of every edge (at most two on a manifold).
  std::vector<int> edge_count(nE, 0);
  std::vector<std::array<int, 2>> edge_half(nE, {-1, -1});
  for (int h = 0; h < H; ++h) {
    const int e = edge_of[h];
    if (edge_count[e] < 2) edge_half[e][edge_count[e]] = h;
    ++edge_count[e];
  }
  for (int e = 0; e < nE; ++e) {
    if (edge_count[e] <= 2) continue;
    const int h0 = edge_half[e][0];
    int a = F_in(h0 / 3, h0 % 3), b = F_in(h0 / 3, (h0 % 3 + 1) % 3);
    std::ostringstream s;
    s << "non-manifold edge (" << std::min(a, b) << ", " << std::max(a, b) << ") shared by " << edge_count[e] << " faces (";
    int listed = 0;
    for (int h = 0; h < H && listed < edge_count[e]; ++h)
      if (edge_of[h] == e) s << (listed++ ? ", " : "") << h / 3;
    s << ")";
    throw Error(s.str());
  }

  // Two independent checks, on two threads for large meshes: non-manifold vertices, and components with
  // their orientation. Their errors are reported in this order, as if one ran after the other.
  std::vector<char> flip(nF, 0);
  std::array<std::exception_ptr, 2> error;
#pragma omp parallel sections num_threads(threads_for(2)) if (nF > kParallelMinElements)
  {
#pragma omp section
    try {
      check_manifold_vertices(F_in, num_vertices, edge_count, edge_half);
    } catch (...) {
      error[0] = std::current_exception();
    }
#pragma omp section
    try {
      orient_components(F_in, edge_count, edge_half, t, flip);
    } catch (...) {
      error[1] = std::current_exception();
    }
  }
  for (const auto& e : error)
    if (e) std::rethrow_exception(e);

  // Oriented faces and their edges.
  t.F = F_in;
  t.face_edges.resize(nF, 3);
  for (int f = 0; f < nF; ++f) {
    if (flip[f]) {
      t.flipped_faces.push_back(f);
      std::swap(t.F(f, 1), t.F(f, 2));
      t.face_edges.row(f) << edge_of[3 * f + 2], edge_of[3 * f + 1], edge_of[3 * f];
    } else {
      t.face_edges.row(f) << edge_of[3 * f], edge_of[3 * f + 1], edge_of[3 * f + 2];
    }
  }
  t.edge_vertices.resize(nE, 2);
  t.edge_faces.setConstant(nE, 2, -1);
  for (int f = 0; f < nF; ++f) {
    for (int k = 0; k < 3; ++k) {
      const int e = t.face_edges(f, k), a = t.F(f, k), b = t.F(f, (k + 1) % 3);
      t.edge_vertices.row(e) << std::min(a, b), std::max(a, b);
      t.edge_faces(e, a < b ? 0 : 1) = f;
    }
  }

  // Vertices: component and faces (CSR), and edges (CSR), on two threads for large meshes.
#pragma omp parallel sections num_threads(threads_for(2)) if (nF > kParallelMinElements)
  {
#pragma omp section
    {
      t.vertex_component.assign(num_vertices, -1);
      t.vertex_face_offsets.assign(num_vertices + 1, 0);
      for (int f = 0; f < nF; ++f)
        for (int k = 0; k < 3; ++k) {
          t.vertex_component[t.F(f, k)] = t.face_component[f];
          ++t.vertex_face_offsets[t.F(f, k) + 1];
        }
      for (int v = 0; v < num_vertices; ++v) t.vertex_face_offsets[v + 1] += t.vertex_face_offsets[v];
      t.vertex_faces.resize(H);
      std::vector<int> fill(t.vertex_face_offsets.begin(), t.vertex_face_offsets.end() - 1);
      for (int f = 0; f < nF; ++f)
        for (int k = 0; k < 3; ++k) t.vertex_faces[fill[t.F(f, k)]++] = f;
    }
#pragma omp section
    {
      t.vertex_edge_offsets.assign(num_vertices + 1, 0);
      for (int e = 0; e < nE; ++e) {
        ++t.vertex_edge_offsets[t.edge_vertices(e, 0) + 1];
        ++t.vertex_edge_offsets[t.edge_vertices(e, 1) + 1];
      }
      for (int v = 0; v < num_vertices; ++v) t.vertex_edge_offsets[v + 1] += t.vertex_edge_offsets[v];
      t.vertex_edges.resize(2 * static_cast<size_t>(nE));
      std::vector<int> fill(t.vertex_edge_offsets.begin(), t.vertex_edge_offsets.end() - 1);
      for (int e = 0; e < nE; ++e)
        for (int k = 0; k < 2; ++k) t.vertex_edges[fill[t.edge_vertices(e, k)]++] = e;
    }
  }
  for (int v = 0; v < num_vertices; ++v)
    if (t.vertex_component[v] < 0) t.unreferenced_vertices.push_back(v);

  // Boundary loops: on a manifold every boundary vertex has exactly one outgoing boundary half-edge.
  std::vector<int> next(num_vertices, -1);
  for (int e = 0; e < nE; ++e) {
    if (!t.is_boundary_edge(e)) continue;
    const int f = t.edge_faces(e, 0) >= 0 ? t.edge_faces(e, 0) : t.edge_faces(e, 1);
    for (int k = 0; k < 3; ++k)
      if (t.face_edges(f, k) == e) next[t.F(f, k)] = t.F(f, (k + 1) % 3);
  }
  t.vertex_boundary_loop.assign(num_vertices, -1);
  for (int v = 0; v < num_vertices; ++v) {
    if (next[v] < 0 || t.vertex_boundary_loop[v] >= 0) continue;
    const int loop = static_cast<int>(t.boundary_loops.size());
    t.boundary_loops.emplace_back();
    for (int u = v; t.vertex_boundary_loop[u] < 0; u = next[u]) {
      t.vertex_boundary_loop[u] = loop;
      t.boundary_loops.back().push_back(u);
    }
    t.components[t.vertex_component[v]].boundary_loops.push_back(loop);
  }

  // Per-component counts and invariants.
  for (int f = 0; f < nF; ++f) ++t.components[t.face_component[f]].faces;
  for (int v = 0; v < num_vertices; ++v)
    if (t.vertex_component[v] >= 0) ++t.components[t.vertex_component[v]].vertices;
  for (int e = 0; e < nE; ++e) {
    const int f = t.edge_faces(e, 0) >= 0 ? t.edge_faces(e, 0) : t.edge_faces(e, 1);
    ++t.components[t.face_component[f]].edges;
  }
  for (auto& c : t.components) {
    c.euler_characteristic = c.vertices - c.edges + c.faces;
    c.genus = (2 - c.euler_characteristic - static_cast<int>(c.boundary_loops.size())) / 2;
  }
  return t;
}

int edge_between(const Topology& t, int i, int j) {
  if (i < 0 || i >= t.num_vertices || j < 0 || j >= t.num_vertices) return -1;
  for (int a = t.vertex_edge_offsets[i]; a < t.vertex_edge_offsets[i + 1]; ++a) {
    const int e = t.vertex_edges[a];
    if (t.edge_vertices(e, 0) == std::min(i, j) && t.edge_vertices(e, 1) == std::max(i, j)) return e;
  }
  return -1;
}

void vertex_fan(const Topology& t, int v, std::vector<int>& out) {
  out.clear();
  const int begin = t.vertex_face_offsets[v], end = t.vertex_face_offsets[v + 1];
  if (begin == end) return;
  const int degree = end - begin;
  auto across = [&](int f, int k) {  // the face across f's edge k, −1 at the boundary
    const int e = t.face_edges(f, k);
    return t.edge_faces(e, 0) == f ? t.edge_faces(e, 1) : t.edge_faces(e, 0);
  };
  int f = t.vertex_faces[begin];
  if (t.is_boundary_vertex(v)) {
    for (int k = 0; k < degree; ++k) {  // clockwise: across the edge from v to its next corner
      const int g = across(f, t.corner_of(f, v));
      if (g < 0) break;
      f = g;
    }
  }
  const int first = f;
  for (int k = 0; k < degree; ++k) {  // counter-clockwise: across the edge from v's previous corner to v
    out.push_back(f);
    const int g = across(f, (t.corner_of(f, v) + 2) % 3);
    if (g < 0 || g == first) break;
    f = g;
  }
}

}  // namespace trivcon
