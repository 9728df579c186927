#pragma once

#include <algorithm>
#include <cstddef>
#include <numeric>
#include <vector>

namespace devsurf::spatial {

/// Disjoint sets of the indices 0 … n−1 (union–find with path halving). A set's representative is
/// its smallest index, so representatives do not depend on the order of the joins.
struct DisjointSets {
  std::vector<int> parent;
  explicit DisjointSets(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  int find(int i) {
    while (parent[static_cast<std::size_t>(i)] != i)
      i = parent[static_cast<std::size_t>(i)] = parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(i)])];
    return i;
  }
  void join(int a, int b) {
    a = find(a);
    b = find(b);
    if (a != b) parent[static_cast<std::size_t>(std::max(a, b))] = std::min(a, b);
  }
};

}  // namespace devsurf::spatial
