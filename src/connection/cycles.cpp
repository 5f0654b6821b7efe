// SPDX-License-Identifier: MIT
#include "trivcon/cycles.h"

#include <algorithm>
#include <map>

#include "trivcon/error.h"

namespace trivcon {

namespace {

DualCycle loop_cycle(const Topology& t, int loop) {
  std::map<int, int> coefficient;  // ordered by edge id, for a deterministic cycle
  for (int v : t.boundary_loops[loop]) {
    for (int a = t.vertex_edge_offsets[v]; a < t.vertex_edge_offsets[v + 1]; ++a) {
      const int e = t.vertex_edges[a];
      if (t.is_boundary_edge(e)) continue;
      coefficient[e] += t.edge_vertices(e, 1) == v ? 1 : -1;
    }
  }
  DualCycle c;
  c.component = t.vertex_component[t.boundary_loops[loop][0]];
  for (auto [e, s] : coefficient)
    if (s != 0) c.edges.push_back(e), c.signs.push_back(s);
  return c;
}

}  // namespace

Cycles compute_cycles(const Topology& t) {
  const int nV = t.num_vertices, nF = t.num_faces, nE = t.num_edges;
  Cycles cycles;
  for (int l = 0; l < static_cast<int>(t.boundary_loops.size()); ++l) cycles.loops.push_back(loop_cycle(t, l));

  // Primal nodes: interior vertices keep their id; boundary loop ℓ is node nV + ℓ.
  auto node_of = [&](int v) { return t.is_boundary_vertex(v) ? nV + t.vertex_boundary_loop[v] : v; };
  const int nNodes = nV + static_cast<int>(t.boundary_loops.size());
  std::vector<int> node_offsets(nNodes + 1, 0), node_edges;
  for (int e = 0; e < nE; ++e) {
    if (t.is_boundary_edge(e)) continue;
    const int a = node_of(t.edge_vertices(e, 0)), b = node_of(t.edge_vertices(e, 1));
    if (a == b) continue;  // joins two vertices of one loop: a self-loop after contraction
    ++node_offsets[a + 1], ++node_offsets[b + 1];
  }
  for (int n = 0; n < nNodes; ++n) node_offsets[n + 1] += node_offsets[n];
  node_edges.resize(node_offsets[nNodes]);
  {
    std::vector<int> fill(node_offsets.begin(), node_offsets.end() - 1);
    for (int e = 0; e < nE; ++e) {
      if (t.is_boundary_edge(e)) continue;
      const int a = node_of(t.edge_vertices(e, 0)), b = node_of(t.edge_vertices(e, 1));
      if (a == b) continue;
      node_edges[fill[a]++] = e, node_edges[fill[b]++] = e;
    }
  }
  // Breadth-first primal tree, from each component's smallest node.
  std::vector<char> in_primal_tree(nE, 0), node_seen(nNodes, 0);
  std::vector<int> queue;
  for (int start = 0; start < nNodes; ++start) {
    if (node_seen[start]) continue;
    if (start < nV && t.vertex_component[start] < 0) continue;  // unreferenced vertex
    node_seen[start] = 1;
    queue.assign(1, start);
    for (size_t q = 0; q < queue.size(); ++q) {
      const int n = queue[q];
      for (int a = node_offsets[n]; a < node_offsets[n + 1]; ++a) {
        const int e = node_edges[a];
        const int other = node_of(t.edge_vertices(e, 0)) == n ? node_of(t.edge_vertices(e, 1)) : node_of(t.edge_vertices(e, 0));
        if (node_seen[other]) continue;
        node_seen[other] = 1;
        in_primal_tree[e] = 1;
        queue.push_back(other);
      }
    }
  }
  // Breadth-first dual tree over faces, avoiding primal tree edges.
  std::vector<int> parent_face(nF, -1), parent_edge(nF, -1), depth(nF, -1);
  std::vector<char> in_dual_tree(nE, 0);
  for (const ComponentInfo& c : t.components) {
    depth[c.first_face] = 0;
    queue.assign(1, c.first_face);
    for (size_t q = 0; q < queue.size(); ++q) {
      const int f = queue[q];
      for (int k = 0; k < 3; ++k) {
        const int e = t.face_edges(f, k);
        if (t.is_boundary_edge(e) || in_primal_tree[e]) continue;
        const int g = t.edge_faces(e, 0) == f ? t.edge_faces(e, 1) : t.edge_faces(e, 0);
        if (depth[g] >= 0) continue;
        depth[g] = depth[f] + 1, parent_face[g] = f, parent_edge[g] = e;
        in_dual_tree[e] = 1;
        queue.push_back(g);
      }
    }
  }
  // One generator per interior edge in neither tree: L → R across e, then R back to L in the dual tree.
  auto cross = [&](DualCycle& c, int from_face, int e) {
    c.edges.push_back(e);
    c.signs.push_back(t.edge_faces(e, 0) == from_face ? 1 : -1);
  };
  std::vector<int> per_component(t.components.size(), 0);
  for (int e = 0; e < nE; ++e) {
    if (t.is_boundary_edge(e) || in_primal_tree[e] || in_dual_tree[e]) continue;
    DualCycle c;
    int a = t.edge_faces(e, 1), b = t.edge_faces(e, 0);  // walk from a (= R) up, and from b (= L) up
    c.component = t.face_component[a];
    cross(c, b, e);
    std::vector<std::pair<int, int>> down;  // (face, edge) steps from the common ancestor back to L, reversed
    while (a != b) {
      if (depth[a] >= depth[b]) {
        cross(c, a, parent_edge[a]);
        a = parent_face[a];
      } else {
        down.emplace_back(parent_face[b], parent_edge[b]);
        b = parent_face[b];
      }
    }
    for (auto it = down.rbegin(); it != down.rend(); ++it) cross(c, it->first, it->second);
    ++per_component[c.component];
    cycles.generators.push_back(std::move(c));
  }
  std::stable_sort(cycles.generators.begin(), cycles.generators.end(),
                   [](const DualCycle& x, const DualCycle& y) { return x.component < y.component; });
  for (size_t c = 0; c < t.components.size(); ++c)
    if (per_component[c] != 2 * t.components[c].genus)
      throw Error("internal error: tree-cotree found " + std::to_string(per_component[c]) + " generators in component " +
                  std::to_string(c) + " of genus " + std::to_string(t.components[c].genus));
  return cycles;
}

double cycle_sum(const DualCycle& cycle, const Eigen::VectorXd& per_edge) {
  double sum = 0;
  for (size_t i = 0; i < cycle.edges.size(); ++i) sum += cycle.signs[i] * per_edge(cycle.edges[i]);
  return sum;
}

double levi_civita_holonomy(const DualCycle& cycle, const Geometry& g) { return cycle_sum(cycle, g.rho); }

double loop_curvature(const Topology& t, const Geometry& g, int loop) {
  double sum = 0;
  for (int v : t.boundary_loops[loop]) sum += g.angle_defect(v);
  return sum;
}

}  // namespace trivcon
