// Neighbour pairs as an order-free set, so tests can compare two welds'
// adjacency (geometry::AdjacentPair lists come in no fixed order).
#pragma once

#include <algorithm>
#include <cstdint>
#include <set>
#include <utility>
#include <vector>

#include "soupuv/geometry/weld.h"

namespace soupuv::testing {

using PairSet = std::set<std::pair<uint32_t, uint32_t>>;

inline PairSet pair_set(const std::vector<geometry::AdjacentPair>& pairs) {
  PairSet s;
  for (const auto& p : pairs) s.insert({std::min(p.a, p.b), std::max(p.a, p.b)});
  return s;
}

}  // namespace soupuv::testing
