// quality::uv_overlap against answers known by hand (eval/uvmetrics.py's
// definitions: utilisation = UV area, overlap = share of rasterised area on
// pixels covered twice or more).
#include "soupuv/quality/uv_overlap.h"

#include <gtest/gtest.h>

#include <random>

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

// The row spans for_each_pixel_centre tests are only a shortcut: it visits
// exactly the centres the full-box edge test accepts. Random triangles,
// slivers in every direction, and vertices and edges on centres (integer
// and half-integer coordinates, where the tie rule decides).
TEST(UvOverlap, PixelCentresOfTheRowSpansAreThoseOfTheWholeBox) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0, 40), angle(0, 6.283185307179586), len(0.5, 30), wid(0.01, 2);
  // The whole box, centre by centre.
  auto brute = [](const T& q, int w, int h) {
    std::vector<std::pair<int, int>> out;
    for (int j = 0; j < h; ++j)
      for (int i = 0; i < w; ++i)
        if (pixel_centre_inside(q, i + 0.5, j + 0.5)) out.push_back({i, j});
    return out;
  };
  size_t visited = 0;
  for (int it = 0; it < 3000; ++it) {
    T q;
    if (it % 3 == 0) {
      q = T{Vec2{u(rng), u(rng)}, Vec2{u(rng), u(rng)}, Vec2{u(rng), u(rng)}};
    } else if (it % 3 == 1) {  // a sliver
      const Vec2 o{u(rng), u(rng)};
      const double a = angle(rng), l = len(rng), w = wid(rng);
      const Vec2 d{std::cos(a), std::sin(a)}, n{-d.y, d.x};
      q = T{o, o + l * d, o + l * d + w * n};
    } else {  // corners on centres and grid lines
      auto g = [&] { return std::round(2 * u(rng)) / 2; };
      q = T{Vec2{g(), g()}, Vec2{g(), g()}, Vec2{g(), g()}};
    }
    if ((q[1].x - q[0].x) * (q[2].y - q[0].y) - (q[1].y - q[0].y) * (q[2].x - q[0].x) < 0) std::swap(q[1], q[2]);
    std::vector<std::pair<int, int>> got;
    for_each_pixel_centre(q, 48, 48, [&](int i, int j) { got.push_back({i, j}); });
    const auto want = brute(q, 48, 48);
    ASSERT_EQ(got, want) << "triangle " << it;
    visited += got.size();
  }
  EXPECT_GT(visited, 10000u);
}

}  // namespace soupuv::quality
