// SPDX-License-Identifier: MIT
#include "linalg/ordering.h"

#include <algorithm>
#include <functional>
#include <numeric>

namespace trivcon::linalg {

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

std::vector<int> coordinate_dissection(const Pattern& pattern, const std::vector<std::array<double, 3>>& point, int leaf) {
  const int n = pattern.n;
  std::vector<int> order(n), side(n, 0), scratch;
  std::iota(order.begin(), order.end(), 0);
  int stamp = 0;
  // The range [b, e) of `order` becomes [its left half's order | its right half's | its separator].
  std::function<void(int, int)> dissect = [&](int b, int e) {
    if (e <= b) return;
    std::array<double, 3> lo = point[order[b]], hi = lo;
    for (int q = b; q < e; ++q)
      for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], point[order[q]][a]), hi[a] = std::max(hi[a], point[order[q]][a]);
    int axis = 0;
    for (int a = 1; a < 3; ++a)
      if (hi[a] - lo[a] > hi[axis] - lo[axis]) axis = a;
    // Ties broken by row, so that the order does not depend on the standard library's algorithms.
    auto before = [&](int x, int y) { return point[x][axis] < point[y][axis] || (point[x][axis] == point[y][axis] && x < y); };
    if (e - b <= std::max(leaf, 2)) {  // a leaf: along its axis (a chain of rows then gets no fill)
      std::sort(order.begin() + b, order.begin() + e, before);
      return;
    }
    const int mid = b + (e - b) / 2;
    std::nth_element(order.begin() + b, order.begin() + mid, order.begin() + e, before);
    const int left = ++stamp, right = ++stamp, separator = ++stamp;
    for (int q = b; q < e; ++q) side[order[q]] = q < mid ? left : right;
    auto touches = [&](int r, int other) {
      for (int k = pattern.start[r]; k < pattern.start[r + 1]; ++k)
        if (side[pattern.neighbour[k]] == other) return true;
      return false;
    };
    int on_left = 0, on_right = 0;
    for (int q = b; q < e; ++q) (q < mid ? on_left : on_right) += touches(order[q], q < mid ? right : left);
    const bool from_left = on_left <= on_right;
    const int sb = from_left ? b : mid, se = from_left ? mid : e;
    for (int q = sb; q < se; ++q)
      if (touches(order[q], from_left ? right : left)) side[order[q]] = separator;
    // The separator's rows to the end of their half (keeping the others' order), then, from the left half,
    // past the right half.
    int cut = sb;
    scratch.clear();
    for (int q = sb; q < se; ++q) {
      if (side[order[q]] == separator)
        scratch.push_back(order[q]);
      else
        order[cut++] = order[q];
    }
    std::copy(scratch.begin(), scratch.end(), order.begin() + cut);
    int left_end = mid, right_begin = mid, right_end = e;
    if (from_left) {
      std::rotate(order.begin() + cut, order.begin() + mid, order.begin() + e);
      left_end = cut, right_begin = cut, right_end = cut + (e - mid);
    } else {
      right_end = cut;
    }
    dissect(b, left_end);
    dissect(right_begin, right_end);
  };
  dissect(0, n);
  return order;
}

}  // namespace trivcon::linalg
