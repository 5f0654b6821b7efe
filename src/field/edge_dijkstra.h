// SPDX-License-Identifier: MIT
// Dijkstra along a mesh's edges (internal to src/field): the distances by which --auto's singularities are
// cancelled, gathered and split (smoothest_field.cpp) and moved onto feature lines (features.cpp).
#pragma once
#include <cmath>
#include <functional>
#include <limits>
#include <queue>
#include <utility>
#include <vector>

#include "trivcon/common.h"
#include "trivcon/topology.h"

namespace trivcon::field {

// From `source`: visit(v, d) for each vertex reached, nearest first; a vertex is expanded when visit returns
// true, and a neighbour reached only while its distance is below `radius` (at most, when `inclusive`). `dist`
// is a work vector of infinities (one per vertex), left so.
template <class Visit>
void edge_dijkstra(const MatrixX3d& V, const Topology& t, int source, double radius, bool inclusive, std::vector<double>& dist, Visit visit) {
  using Item = std::pair<double, int>;
  std::vector<int> touched{source};
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> queue;
  dist[source] = 0, queue.emplace(0.0, source);
  while (!queue.empty()) {
    auto [d, v] = queue.top();
    queue.pop();
    if (d > dist[v] || !visit(v, d)) continue;
    for (int q = t.vertex_edge_offsets[v]; q < t.vertex_edge_offsets[v + 1]; ++q) {
      const int e = t.vertex_edges[q];
      const int w = t.edge_vertices(e, 0) == v ? t.edge_vertices(e, 1) : t.edge_vertices(e, 0);
      const double dw = d + (V.row(t.edge_vertices(e, 1)) - V.row(t.edge_vertices(e, 0))).norm();
      if ((inclusive ? dw <= radius : dw < radius) && dw < dist[w]) {
        if (std::isinf(dist[w])) touched.push_back(w);
        dist[w] = dw, queue.emplace(dw, w);
      }
    }
  }
  for (int v : touched) dist[v] = std::numeric_limits<double>::infinity();
}

}  // namespace trivcon::field
