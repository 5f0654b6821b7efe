#include "ordering.h"

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

std::vector<int> coordinate_dissection(const Pattern& pattern, const std::vector<std::array<float, 3>>& position, int leaf) {
  const int n = pattern.n;
  std::vector<int> set(n, -1), rows(n), side(n, 0);
  std::iota(rows.begin(), rows.end(), 0);
  int sets = 0, stamp = 0;
  std::vector<int> separator;
  // Splits rows[begin, end): the two halves are dissected first, then their separator gets the next set.
  auto dissect = [&](auto&& self, int begin, int end) -> void {
    const int size = end - begin;
    if (size <= leaf) {
      for (int k = begin; k < end; ++k) set[rows[k]] = sets;
      ++sets;
      return;
    }
    std::array<float, 3> low = position[rows[begin]], high = low;
    for (int k = begin; k < end; ++k)
      for (int d = 0; d < 3; ++d) low[d] = std::min(low[d], position[rows[k]][d]), high[d] = std::max(high[d], position[rows[k]][d]);
    int axis = 0;
    for (int d = 1; d < 3; ++d)
      if (high[d] - low[d] > high[axis] - low[axis]) axis = d;
    const int middle = begin + size / 2;
    std::nth_element(rows.begin() + begin, rows.begin() + middle, rows.begin() + end, [&](int a, int b) {
      return position[a][axis] < position[b][axis] || (position[a][axis] == position[b][axis] && a < b);
    });
    // side: +stamp for the lower half, −stamp for the upper half of this part (other parts differ).
    ++stamp;
    for (int k = begin; k < end; ++k) side[rows[k]] = k < middle ? stamp : -stamp;
    auto on_cut = [&](int r) {
      for (int q = pattern.start[r]; q < pattern.start[r + 1]; ++q)
        if (side[pattern.neighbour[q]] == -side[r]) return true;
      return false;
    };
    int lower_cut = 0, upper_cut = 0;
    for (int k = begin; k < end; ++k) (k < middle ? lower_cut : upper_cut) += on_cut(rows[k]);
    const bool cut_lower = lower_cut <= upper_cut;
    // Keep the rows that are not on the cut, lower half then upper half; the separator aside.
    separator.clear();
    int kept = begin, lower_end = begin;
    for (int k = begin; k < end; ++k) {
      const int r = rows[k];
      if ((k < middle) == cut_lower && on_cut(r)) {
        separator.push_back(r);
      } else {
        rows[kept++] = r;
        if (k < middle) lower_end = kept;
      }
    }
    std::vector<int> own(separator);
    self(self, begin, lower_end);
    self(self, lower_end, kept);
    for (int r : own) set[r] = sets;
    ++sets;
  };
  dissect(dissect, 0, n);
  return set;
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
