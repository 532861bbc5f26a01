// Whether two groups of corners (given as their triangles' ids) share a
// triangle: the welds' test that a join would not collapse a triangle.
//
// Input : the soup's triangle count; per call, two lists of triangle ids.
// Output: true if some id is in both lists.
// Cost  : O(|x| + |y|): the smaller list is stamped, the larger looked up.
//         (Comparing every pair was 3.9 s of a 124k scan's weld, where the
//         tolerance spans several edges and groups grow to hundreds.)
#pragma once

#include <cstdint>
#include <vector>

namespace soupuv::geometry {

class SharedTriangleTest {
 public:
  explicit SharedTriangleTest(size_t triangles) : stamp_(triangles, UINT32_MAX) {}

  bool operator()(const std::vector<uint32_t>& x, const std::vector<uint32_t>& y) {
    const auto& small = x.size() <= y.size() ? x : y;
    const auto& large = x.size() <= y.size() ? y : x;
    ++round_;
    for (uint32_t t : small) stamp_[t] = round_;
    for (uint32_t u : large)
      if (stamp_[u] == round_) return true;
    return false;
  }

 private:
  std::vector<uint32_t> stamp_;
  uint32_t round_ = 0;
};

}  // namespace soupuv::geometry
