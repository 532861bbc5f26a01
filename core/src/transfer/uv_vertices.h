// The UV vertices of a map after transfer (private to the transfer module):
// one per (welded vertex, chart), with the corners that use each, so the UV
// repair and the re-weld can move all copies of a vertex on one chart as one.
//
// Input : a weld (corner -> welded vertex) and each soup triangle's chart.
// Output: corner -> UV vertex, and per UV vertex its corners (CSR: corners
//         start[v] .. start[v+1]-1), ids in order of first use.
// Cost  : O(corners) expected.
#pragma once

#include <cstdint>
#include <numeric>
#include <unordered_map>
#include <vector>

#include "soupuv/quality/weld.h"

namespace soupuv::transfer::detail {

struct UvVertices {
  std::vector<uint32_t> of_corner;  // corner -> UV vertex
  std::vector<uint32_t> start, corners;
  size_t count() const { return start.size() - 1; }
};

inline UvVertices uv_vertices(const quality::Weld& weld, const std::vector<int>& triangle_chart) {
  UvVertices v;
  const size_t corners = weld.corner_vertex.size();
  v.of_corner.resize(corners);
  std::unordered_map<uint64_t, uint32_t> id;
  id.reserve(corners);
  for (size_t c = 0; c < corners; ++c) {
    const uint64_t key = (uint64_t(weld.corner_vertex[c]) << 32) | uint32_t(triangle_chart[c / 3]);
    auto [it, fresh] = id.try_emplace(key, uint32_t(id.size()));
    v.of_corner[c] = it->second;
  }
  v.start.assign(id.size() + 1, 0);
  for (uint32_t u : v.of_corner) ++v.start[u + 1];
  std::partial_sum(v.start.begin(), v.start.end(), v.start.begin());
  std::vector<uint32_t> fill(v.start.begin(), v.start.end() - 1);
  v.corners.resize(corners);
  for (size_t c = 0; c < corners; ++c) v.corners[fill[v.of_corner[c]]++] = uint32_t(c);
  return v;
}

}  // namespace soupuv::transfer::detail
