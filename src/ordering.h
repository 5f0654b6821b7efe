// Internal to the solver: fill-reducing orders for the vertex block of the normal matrix (see solver.cpp).
#pragma once
#include <array>
#include <vector>

namespace trivcon::ordering {

// The symmetric sparsity pattern of the leading n × n block of a matrix given as its upper triangle in
// compressed columns (outer, inner): per row, its off-diagonal neighbours.
struct Pattern {
  int n = 0;
  std::vector<int> start, neighbour;  // neighbours of row r: neighbour[start[r] … start[r + 1])
};
Pattern leading_block_pattern(const std::vector<int>& outer, const std::vector<int>& inner, int n);

// Nested dissection by coordinate bisection: each part is split at the median of its longest extent,
// the smaller set of vertices with a neighbour across the cut is its separator, down to parts of at
// most `leaf` rows. Returns a constraint set per row (for CAMD): parts before their separators, so
// that the sets, in increasing order, are a postorder of the dissection tree. O(n log n).
std::vector<int> coordinate_dissection(const Pattern& pattern, const std::vector<std::array<float, 3>>& position, int leaf);

// The elimination tree of the block in the order `order` (order[k] = row eliminated k-th), Liu's
// algorithm: parent[k] (positions), −1 at roots.
std::vector<int> elimination_tree(const Pattern& pattern, const std::vector<int>& order);

}  // namespace trivcon::ordering
