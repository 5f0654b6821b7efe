#include "detail/ordering.h"

#include <algorithm>
#include <numeric>

namespace trivcon::ordering {

Pattern leading_block_pattern(const std::vector<int>& outer, const std::vector<int>& inner, int n) {
  Pattern p;
  p.n = n;
  p.start.assign(static_cast<size_t>(n) + 1, 0);
  for (int c = 0; c < n; ++c)
    for (int k = outer[c]; k < outer[c + 1]; ++k)
      if (inner[k] != c) ++p.start[c + 1], ++p.start[inner[k] + 1];
  std::partial_sum(p.start.begin(), p.start.end(), p.start.begin());
  std::vector<int> fill(p.start.begin(), p.start.end() - 1);
  p.neighbour.resize(p.start[n]);
  for (int c = 0; c < n; ++c)
    for (int k = outer[c]; k < outer[c + 1]; ++k)
      if (inner[k] != c) p.neighbour[fill[c]++] = inner[k], p.neighbour[fill[inner[k]]++] = c;
  return p;
}

std::vector<int> elimination_tree(const Pattern& pattern, const std::vector<int>& order) {
  const int n = pattern.n;
  std::vector<int> position(n), parent(n, -1), ancestor(n, -1);
  for (int k = 0; k < n; ++k) position[order[k]] = k;
  for (int k = 0; k < n; ++k) {
    const int v = order[k];
    for (int q = pattern.start[v]; q < pattern.start[v + 1]; ++q) {
      for (int i = position[pattern.neighbour[q]]; i != -1 && i < k;) {
        const int up = ancestor[i];
        ancestor[i] = k;
        if (up == -1) parent[i] = k;
        i = up;
      }
    }
  }
  return parent;
}

}  // namespace trivcon::ordering
