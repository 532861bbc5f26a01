// The weld's adjacent pairs listed by triangle (private to the UV solve):
// the pairs of triangle t are pairs[index[k]] for k in [first[t], first[t+1]).
// Each pair is listed under both of its triangles. The merges find a seam's
// pairs from the smaller island's triangles this way, instead of scanning
// every pair per attempt.
#pragma once

#include <cstdint>
#include <vector>

#include "soupuv/geometry/weld.h"

namespace soupuv::uvsolve::detail {

struct PairsByTriangle {
  std::vector<uint32_t> first, index;

  PairsByTriangle(const std::vector<geometry::AdjacentPair>& pairs, size_t triangles)
      : first(triangles + 1, 0), index(2 * pairs.size()) {
    for (const auto& p : pairs) ++first[p.a + 1], ++first[p.b + 1];
    for (size_t t = 0; t < triangles; ++t) first[t + 1] += first[t];
    std::vector<uint32_t> at(first.begin(), first.end() - 1);
    for (uint32_t i = 0; i < pairs.size(); ++i) index[at[pairs[i].a]++] = i, index[at[pairs[i].b]++] = i;
  }
};

}  // namespace soupuv::uvsolve::detail
