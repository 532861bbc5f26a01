// quality::uv_overlap against answers known by hand (eval/uvmetrics.py's
// definitions: utilisation = UV area, overlap = share of rasterised area on
// pixels covered twice or more).
#include "soupuv/quality/uv_overlap.h"

#include <gtest/gtest.h>

namespace soupuv::quality {
namespace {

using T = std::array<Vec2, 3>;

TEST(UvOverlap, SquareInTwoTrianglesIsFullAndSingle) {
  const std::vector<T> uv = {T{Vec2{0, 0}, Vec2{1, 0}, Vec2{1, 1}}, T{Vec2{0, 0}, Vec2{1, 1}, Vec2{0, 1}}};
  const UvOverlap o = uv_overlap(uv, {1, 1});
  EXPECT_NEAR(o.utilisation, 1.0, 1e-12);
  EXPECT_EQ(o.overlap, 0.0) << "two triangles sharing a diagonal share no pixel centre";
}

TEST(UvOverlap, TheSameTriangleTwiceIsAllOverlap) {
  const T t{Vec2{0.1, 0.1}, Vec2{0.6, 0.1}, Vec2{0.1, 0.6}};
  const T mirrored{t[0], t[2], t[1]};  // clockwise: counted the same
  const UvOverlap o = uv_overlap({t, mirrored}, {1, 1});
  EXPECT_NEAR(o.utilisation, 2 * 0.125, 1e-12);
  EXPECT_EQ(o.overlap, 1.0);
}

TEST(UvOverlap, HalfCoveredTwiceAndExcludedTriangles) {
  // A square [0,0.5]^2 in two triangles, one of them twice, and a fourth
  // triangle that is not counted.
  const std::vector<T> uv = {T{Vec2{0, 0}, Vec2{0.5, 0}, Vec2{0.5, 0.5}}, T{Vec2{0, 0}, Vec2{0.5, 0.5}, Vec2{0, 0.5}},
                             T{Vec2{0, 0}, Vec2{0.5, 0}, Vec2{0.5, 0.5}}, T{Vec2{0.9, 0.9}, Vec2{1, 0.9}, Vec2{1, 1}}};
  // Triangle 2 repeats triangle 0 (1/2 of the square's pixels, counted
  // twice): 2 x 1/2 over 1 + 1/2 layers = 2/3. Triangle 3 is excluded.
  const UvOverlap o = uv_overlap(uv, {1, 1, 1, 0});
  EXPECT_NEAR(o.utilisation, 3 * 0.125, 1e-12);
  EXPECT_NEAR(o.overlap, 2.0 / 3.0, 0.01);
}

}  // namespace
}  // namespace soupuv::quality
