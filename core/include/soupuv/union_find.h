// Disjoint sets over 0..n-1 with path halving. unite() makes the smaller
// root the representative, so find() of a set is its smallest member and
// results never depend on the order of unions.
#pragma once

#include <algorithm>
#include <cstdint>
#include <numeric>
#include <vector>

namespace soupuv {

struct UnionFind {
  std::vector<uint32_t> parent;

  explicit UnionFind(size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0u); }

  uint32_t find(uint32_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }

  void unite(uint32_t a, uint32_t b) {
    a = find(a);
    b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
};

}  // namespace soupuv
