// Internal to the solver: the pattern and elimination tree of the normal matrix's vertex block, to
// postorder a fill-reducing order (see CholeskyEngine::vertex_order in solver.cpp).
#pragma once
#include <vector>

namespace trivcon::ordering {

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

}  // namespace trivcon::ordering
