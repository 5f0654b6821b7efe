// SPDX-License-Identifier: MIT
// Internal: fill-reducing orders and their elimination trees.
// - The pattern and elimination tree of the normal matrix's vertex block, to postorder a fill-reducing order
//   (see vertex_order in src/connection/cholesky_engine.cpp).
// - A nested dissection by coordinates, the second candidate order of the smoothest field's matrix
//   (trivcon/auto.h).
#pragma once
#include <array>
#include <vector>

namespace trivcon::linalg {

// The symmetric sparsity pattern of the leading n × n block of a matrix given as its upper triangle in
// compressed columns (outer, inner): per row, its off-diagonal neighbours.
struct Pattern {
  int n = 0;
  std::vector<int> start, neighbour;  // neighbours of row r: neighbour[start[r] … start[r + 1])
};
Pattern leading_block_pattern(const std::vector<int>& outer, const std::vector<int>& inner, int n);

// The elimination tree of the block in the order `order` (order[k] = row eliminated k-th), Liu's
// algorithm: parent[k] (positions), −1 at roots. (cholmod_etree would need the permuted matrix, a copy of
// the whole block; this works on the unpermuted pattern through the positions.)
std::vector<int> elimination_tree(const Pattern& pattern, const std::vector<int>& order);

// A nested dissection order (order[k] = row eliminated k-th) of a pattern whose rows have points in space
// (a mesh's faces by their centroids): the rows are split at the median of the axis along which their
// points spread most; the rows of the smaller side that have a neighbour on the other side are the
// separator, ordered after both halves, which are ordered the same way, down to `leaf` rows (sorted along
// their own longest axis). Why not METIS_NodeND, which finds smaller separators: it takes many times as
// long as this. Why not only this: on scanned meshes its plane cuts meet the surface in long curves and it
// needs several times AMD's flops (BENCHMARKS.md, "Figures that were in code comments"), so it is a candidate to
// compare, not a replacement (the smoothest field takes the one with fewer flops, docs/auto.md). Deterministic.
std::vector<int> coordinate_dissection(const Pattern& pattern, const std::vector<std::array<double, 3>>& point, int leaf = 16);

}  // namespace trivcon::linalg
