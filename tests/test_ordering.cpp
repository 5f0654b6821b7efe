// SPDX-License-Identifier: MIT
// The fill-reducing orders of src/linalg/ordering.h (internal): the coordinate dissection against AMD and
// against the fill it must avoid, through CHOLMOD's own symbolic analysis.
#include <cholmod.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <map>
#include <numeric>
#include <random>
#include <vector>

#include "linalg/cholmod.h"
#include "linalg/ordering.h"
#include "trivcon/generate.h"
#include "trivcon/topology.h"

using namespace trivcon;

namespace {

// A symmetric pattern given by its upper triangle (compressed columns, diagonal included) and a point per row.
struct Graph {
  int n = 0;
  std::vector<int> outer, inner;
  std::vector<double> values;
  std::vector<std::array<double, 3>> point;
};

Graph from_edges(int n, const std::vector<std::pair<int, int>>& edges, std::vector<std::array<double, 3>> point) {
  std::vector<std::vector<int>> above(n);
  for (auto [a, b] : edges) above[std::max(a, b)].push_back(std::min(a, b));
  Graph g;
  g.n = n, g.point = std::move(point);
  g.outer.push_back(0);
  for (int c = 0; c < n; ++c) {
    std::sort(above[c].begin(), above[c].end());
    for (int r : above[c]) g.inner.push_back(r), g.values.push_back(-1.0);
    g.inner.push_back(c), g.values.push_back(4.0);
    g.outer.push_back(static_cast<int>(g.inner.size()));
  }
  return g;
}

// The dual graph of a mesh: a row per face at its centroid, an entry per interior edge.
Graph dual_graph(const Mesh& mesh) {
  const Topology t = build_topology(mesh.F, static_cast<int>(mesh.V.rows()));
  std::vector<std::pair<int, int>> edges;
  for (int e = 0; e < t.num_edges; ++e)
    if (!t.is_boundary_edge(e)) edges.emplace_back(t.edge_faces(e, 0), t.edge_faces(e, 1));
  std::vector<std::array<double, 3>> point(t.num_faces);
  for (int f = 0; f < t.num_faces; ++f)
    for (int a = 0; a < 3; ++a) point[f][a] = (mesh.V(mesh.F(f, 0), a) + mesh.V(mesh.F(f, 1), a) + mesh.V(mesh.F(f, 2), a)) / 3;
  return from_edges(t.num_faces, edges, point);
}

struct Fill {
  double lnz = 0, flops = 0;
};

// CHOLMOD's count of the factor's nonzeros and flops for an order (empty: CHOLMOD's AMD).
Fill analyse(const Graph& g, std::vector<int> order) {
  linalg::CholmodContext context;
  cholmod_common& c = *context;
  c.nmethods = 1;
  c.method[0].ordering = order.empty() ? CHOLMOD_AMD : CHOLMOD_GIVEN;
  c.postorder = 1;
  cholmod_sparse A = linalg::upper_view(g.outer, g.inner, g.values, g.n);
  cholmod_factor* L = order.empty() ? cholmod_analyze(&A, &c) : cholmod_analyze_p(&A, order.data(), nullptr, 0, &c);
  EXPECT_NE(L, nullptr);
  Fill f{c.lnz, c.fl};
  cholmod_free_factor(&L, &c);
  return f;
}

std::vector<int> dissection(const Graph& g, int leaf = 16) {
  return linalg::coordinate_dissection(linalg::leading_block_pattern(g.outer, g.inner, g.n), g.point, leaf);
}

void expect_permutation(const std::vector<int>& order, int n) {
  ASSERT_EQ(static_cast<int>(order.size()), n);
  std::vector<int> sorted = order;
  std::sort(sorted.begin(), sorted.end());
  for (int k = 0; k < n; ++k) ASSERT_EQ(sorted[k], k);
}

}  // namespace

TEST(CoordinateDissection, IsADeterministicPermutation) {
  const Graph g = dual_graph(make_cube_sphere(30, true));
  const std::vector<int> order = dissection(g);
  expect_permutation(order, g.n);
  EXPECT_EQ(order, dissection(g));
  // Coincident points (every row at the origin): still a permutation, and a valid one to analyse.
  Graph same = g;
  for (auto& p : same.point) p = {0, 0, 0};
  expect_permutation(dissection(same), same.n);
  expect_permutation(dissection(from_edges(1, {}, {{{0, 0, 0}}})), 1);
  expect_permutation(dissection(from_edges(0, {}, {})), 0);
}

// A chain of rows along a line, numbered at random: every separator is one row and the leaves are sorted
// along the line, so the fill is at most one entry per row (to the separator at the end of its piece):
// fewer than 3n entries in all.
TEST(CoordinateDissection, AChainGetsOneFillEntryPerRowAtMost) {
  const int n = 1000;
  std::vector<int> id(n);
  std::iota(id.begin(), id.end(), 0);
  std::shuffle(id.begin(), id.end(), std::mt19937(3));  // row id[i] is the i-th along the line
  std::vector<std::pair<int, int>> edges;
  std::vector<std::array<double, 3>> point(n);
  for (int i = 0; i < n; ++i) point[id[i]] = {0.5 * i, 0.0, 0.0};
  for (int i = 0; i + 1 < n; ++i) edges.emplace_back(id[i], id[i + 1]);
  const Graph g = from_edges(n, edges, point);
  for (int leaf : {2, 16, 64}) {
    const Fill f = analyse(g, dissection(g, leaf));
    EXPECT_LE(f.lnz, 3.0 * n) << "leaf " << leaf;
  }

}

// A leaf is sorted along its widest axis: a 20 × 20 grid numbered at random and taken as one leaf is then
// eliminated column by column, a band of width 20 (at most 21 entries per column of the factor), where
// its random numbering fills nearly twice as much.
TEST(CoordinateDissection, ALeafIsOrderedAlongItsAxis) {
  const int side = 20, n = side * side;
  std::vector<int> id(n);
  std::iota(id.begin(), id.end(), 0);
  std::shuffle(id.begin(), id.end(), std::mt19937(5));  // row id[i * side + j] sits at (1.5 i, j): wider along x
  std::vector<std::array<double, 3>> point(n);
  std::vector<std::pair<int, int>> edges;
  for (int i = 0; i < side; ++i)
    for (int j = 0; j < side; ++j) {
      point[id[i * side + j]] = {1.5 * i, 1.0 * j, 0.0};
      if (i + 1 < side) edges.emplace_back(id[i * side + j], id[(i + 1) * side + j]);
      if (j + 1 < side) edges.emplace_back(id[i * side + j], id[i * side + j + 1]);
    }
  const Graph g = from_edges(n, edges, point);
  const Fill leaf = analyse(g, dissection(g, n));
  EXPECT_LE(leaf.lnz, n * (side + 1.0));
  std::vector<int> given(n);
  std::iota(given.begin(), given.end(), 0);
  EXPECT_GT(analyse(g, given).lnz, 1.5 * leaf.lnz);
}

// Why it exists: on a regular grid of faces (the cube and the cube-like sphere) minimum degree fills more
// than a nested dissection does, the more so the larger the grid (at 400k faces 7.0e9 flops against 3.9e9).
TEST(CoordinateDissection, BeatsMinimumDegreeOnARegularGrid) {
  for (const bool spherical : {false, true}) {
    const Graph g = dual_graph(make_cube_sphere(100, spherical));  // 120,000 faces
    const Fill nd = analyse(g, dissection(g)), amd = analyse(g, {});
    EXPECT_LT(nd.flops, 0.8 * amd.flops) << "spherical " << spherical << ": " << nd.flops << " against " << amd.flops;
    // And far less than no order at all (the rows as generated).
    std::vector<int> natural(g.n);
    std::iota(natural.begin(), natural.end(), 0);
    EXPECT_LT(nd.lnz, 0.5 * analyse(g, natural).lnz);
  }
}
