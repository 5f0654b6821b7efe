// SPDX-License-Identifier: MIT
// The constraint system as matrices (src/connection/assembly.h).
#include "connection/assembly.h"

#include <algorithm>
#include <numeric>
#include <utility>

namespace trivcon::connection {

using Triplet = Eigen::Triplet<double>;

Csc normal_matrix(const EdgeEnds& ends, int nV, const SparseMatrix& Et, const SparseMatrix& Ct, const Eigen::VectorXd& w, EdgeRows& edges) {
  const int m = static_cast<int>(ends.size()), nD = nV + static_cast<int>(Et.cols()), nC = static_cast<int>(Ct.cols());
  const int n = nD + nC;
  // The rows of A touching each edge, by counting.
  std::vector<int>& start = edges.start;
  start.assign(static_cast<size_t>(m) + 1, 0);
  auto for_each_sparse_entry = [&](auto&& visit) {  // (row of A, edge, coefficient) of Et and Ct
    for (int c = 0; c < static_cast<int>(Et.cols()); ++c)
      for (SparseMatrix::InnerIterator it(Et, c); it; ++it) visit(nV + c, static_cast<int>(it.row()), it.value());
    for (int c = 0; c < nC; ++c)
      for (SparseMatrix::InnerIterator it(Ct, c); it; ++it) visit(nD + c, static_cast<int>(it.row()), it.value());
  };
  for (int a = 0; a < m; ++a) start[a + 1] = (ends[a][0] >= 0) + (ends[a][1] >= 0);
  for_each_sparse_entry([&](int, int a, double) { ++start[a + 1]; });
  std::partial_sum(start.begin(), start.end(), start.begin());
  std::vector<int>& row_of = edges.row;
  std::vector<double>& coefficient = edges.coefficient;
  row_of.resize(start[m]), coefficient.resize(start[m]);
  std::vector<int> next(start.begin(), start.end() - 1);
  for (int a = 0; a < m; ++a)
    for (int end = 0; end < 2; ++end)
      if (ends[a][end] >= 0) row_of[next[a]] = ends[a][end], coefficient[next[a]++] = end == 0 ? -1.0 : 1.0;
  for_each_sparse_entry([&](int r, int a, double v) { row_of[next[a]] = r, coefficient[next[a]++] = v; });
  // Per vertex row, its edges as (the other end's row or −1, weight): a vertex column of M holds only
  // vertex rows (the others come after it), so it is read from this list in sequence.
  std::vector<int> incident_start(static_cast<size_t>(nV) + 1, 0);
  for (int a = 0; a < m; ++a)
    for (int end = 0; end < 2; ++end)
      if (ends[a][end] >= 0) ++incident_start[ends[a][end] + 1];
  std::partial_sum(incident_start.begin(), incident_start.end(), incident_start.begin());
  std::vector<std::pair<int, double>> incident(incident_start[nV]);
  next.assign(incident_start.begin(), incident_start.end() - 1);
  for (int a = 0; a < m; ++a)
    for (int end = 0; end < 2; ++end)
      if (ends[a][end] >= 0) incident[next[ends[a][end]]++] = {ends[a][1 - end], w(a)};

  Csc M;
  M.outer.assign(static_cast<size_t>(n) + 1, 0);
  M.inner.reserve(static_cast<size_t>(start[m]) * 2 + n);
  M.values.reserve(M.inner.capacity());
  std::vector<double> sum(n, 0.0);
  std::vector<int> seen(n, -1), rows;
  auto add_edge = [&](int c, int a, double scale) {
    for (int k = start[a]; k < start[a + 1]; ++k) {
      const int r = row_of[k];
      if (r > c) continue;
      if (seen[r] != c) seen[r] = c, sum[r] = 0, rows.push_back(r);
      sum[r] += scale * coefficient[k];
    }
  };
  std::vector<std::pair<int, double>> column;
  for (int c = 0; c < n; ++c) {
    rows.clear();
    if (c < nV) {  // −w to each neighbouring row above the diagonal, Σ w on it (one edge per vertex pair)
      column.clear();
      double diagonal = 0;
      for (int k = incident_start[c]; k < incident_start[c + 1]; ++k) {
        const auto [other, weight] = incident[k];
        diagonal += weight;
        if (other >= 0 && other < c) column.emplace_back(other, -weight);
      }
      std::sort(column.begin(), column.end());
      for (const auto& [r, v] : column) M.inner.push_back(r), M.values.push_back(v);
      M.inner.push_back(c), M.values.push_back(diagonal);
      M.outer[c + 1] = static_cast<int>(M.inner.size());
      continue;
    }
    const SparseMatrix& S = c < nD ? Et : Ct;
    for (SparseMatrix::InnerIterator it(S, c < nD ? c - nV : c - nD); it; ++it)
      add_edge(c, static_cast<int>(it.row()), it.value() * w(static_cast<int>(it.row())));
    std::sort(rows.begin(), rows.end());
    for (int r : rows) M.inner.push_back(r), M.values.push_back(sum[r]);
    M.outer[c + 1] = static_cast<int>(M.inner.size());
  }
  return M;
}

RowLayout row_layout(const Topology& t) {
  RowLayout r;
  r.vertex_row.assign(t.num_vertices, -1);
  r.dropped_vertex.assign(t.components.size(), -1);
  r.dropped_loop.assign(t.components.size(), -1);
  for (size_t c = 0; c < t.components.size(); ++c)
    for (int l : t.components[c].boundary_loops)
      if (r.dropped_loop[c] < 0 || t.boundary_loops[l].size() > t.boundary_loops[r.dropped_loop[c]].size()) r.dropped_loop[c] = l;
  for (int v = t.num_vertices - 1; v >= 0; --v) {
    if (!t.is_interior_vertex(v)) continue;
    const int c = t.vertex_component[v];
    if (t.components[c].boundary_loops.empty() && r.dropped_vertex[c] < 0) r.dropped_vertex[c] = v;
  }
  for (int v = 0; v < t.num_vertices; ++v)
    if (t.is_interior_vertex(v) && r.dropped_vertex[t.vertex_component[v]] != v) r.vertex_row[v] = r.num_vertex_rows++;
  return r;
}
std::vector<int> loop_rows(const Topology& t, const std::vector<int>& dropped_loop) {
  std::vector<int> loops;
  for (size_t l = 0; l < t.boundary_loops.size(); ++l)
    if (dropped_loop[t.vertex_component[t.boundary_loops[l][0]]] != static_cast<int>(l)) loops.push_back(static_cast<int>(l));
  return loops;
}
void system_edges(const Topology& t, const Eigen::VectorXd* positive_only, std::vector<int>& edges, std::vector<int>& column) {
  edges.clear();
  column.assign(t.num_edges, -1);
  for (int e = 0; e < t.num_edges; ++e)
    if (positive_only ? (*positive_only)(e) > 0 : !t.is_boundary_edge(e)) column[e] = static_cast<int>(edges.size()), edges.push_back(e);
}
EdgeEnds edge_ends(const Topology& t, const std::vector<int>& edges, const std::vector<int>& vertex_row) {
  EdgeEnds ends(edges.size());
  for (size_t a = 0; a < edges.size(); ++a)
    for (int end = 0; end < 2; ++end) ends[a][end] = vertex_row[t.edge_vertices(edges[a], end)];
  return ends;
}
SparseMatrix cycle_columns(int m, const std::vector<int>& column, int count, const std::function<const DualCycle&(int)>& cycle) {
  std::vector<Triplet> trip;
  for (int r = 0; r < count; ++r) {
    const DualCycle& c = cycle(r);
    for (size_t k = 0; k < c.edges.size(); ++k)
      if (column[c.edges[k]] >= 0) trip.emplace_back(column[c.edges[k]], r, c.signs[k]);
  }
  SparseMatrix S(m, count);
  S.setFromTriplets(trip.begin(), trip.end());
  return S;
}

}  // namespace trivcon::connection
