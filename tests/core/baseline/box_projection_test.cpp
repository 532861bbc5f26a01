// Box projection baseline: every face in its own cell of the 3x2 grid, one
// common scale (distances on a face keep their ratios), outside views keep
// orientation, and all UVs lie in [0,1]^2.
#include <gtest/gtest.h>

#include <cmath>

#include "soupuv/baseline/box_projection.h"
#include "soupuv/errors.h"
#include "testing/shapes.h"

namespace soupuv::baseline {
namespace {

double signed_area(const std::vector<Vec2>& uv, size_t t) {
  return 0.5 * cross(uv[t * 3 + 1] - uv[t * 3], uv[t * 3 + 2] - uv[t * 3]);
}

int face_of(const Soup& soup, size_t t) {
  Vec3 n = triangle_normal(soup, t);
  int k = 0;
  for (int c = 1; c < 3; ++c)
    if (std::fabs(n[c]) > std::fabs(n[k])) k = c;
  return k + (n[k] < 0 ? 3 : 0);
}

TEST(BoxProjection, CubeFacesFillTheirOwnCells) {
  Soup soup = shapes::to_soup(shapes::cube(2.0, 4));
  BoxOptions options;
  options.padding = 0.02;
  BoxResult r = box_projection(soup, options);
  ASSERT_EQ(r.corner_uvs.size(), soup.triangles.size() * 3);
  for (size_t f = 0; f < 6; ++f) EXPECT_EQ(r.face_triangles[f], soup.triangles.size() / 6) << f;
  for (size_t t = 0; t < soup.triangles.size(); ++t) {
    int f = face_of(soup, t);
    double u0 = (f % 3) / 3.0, v0 = (f / 3) / 2.0;
    for (int c = 0; c < 3; ++c) {
      Vec2 uv = r.corner_uvs[t * 3 + c];
      EXPECT_GE(uv.x, u0 + options.padding - 1e-12);
      EXPECT_LE(uv.x, u0 + 1.0 / 3 - options.padding + 1e-12);
      EXPECT_GE(uv.y, v0 + options.padding - 1e-12);
      EXPECT_LE(uv.y, v0 + 1.0 / 2 - options.padding + 1e-12);
    }
  }
}

TEST(BoxProjection, OneScaleForAllFaces) {
  // On a cube every triangle lies in its projection plane, so UV lengths are
  // 3D lengths times one constant.
  Soup soup = shapes::to_soup(shapes::cube(3.0, 3));
  BoxResult r = box_projection(soup);
  double ratio = -1;
  for (size_t t = 0; t < soup.triangles.size(); ++t)
    for (int c = 0; c < 3; ++c) {
      double len3 = norm(soup.corner(t, (c + 1) % 3) - soup.corner(t, c));
      double len2 = norm(r.corner_uvs[t * 3 + (c + 1) % 3] - r.corner_uvs[t * 3 + c]);
      if (ratio < 0) ratio = len2 / len3;
      EXPECT_NEAR(len2 / len3, ratio, 1e-12);
    }
  EXPECT_NEAR(ratio, (1.0 / 3 - 2 * 0.01) / 3.0, 1e-12);
}

TEST(BoxProjection, OutsideViewsKeepOrientation) {
  // A closed surface wound consistently: seen from outside, every face image
  // must wind the same way (no mirrored faces).
  Soup soup = shapes::to_soup(shapes::icosphere(1.0, 3), 0.0);
  BoxResult r = box_projection(soup);
  size_t negative = 0, positive = 0;
  for (size_t t = 0; t < soup.triangles.size(); ++t)
    (signed_area(r.corner_uvs, t) < 0 ? negative : positive)++;
  EXPECT_TRUE(negative == 0 || positive == 0) << negative << " vs " << positive;
}

TEST(BoxProjection, NoisySoupStaysInUnitSquare) {
  Soup soup = shapes::to_soup(shapes::torus(1.0, 0.3, 40, 20), 1e-3, 7);
  BoxResult r = box_projection(soup);
  for (const Vec2& uv : r.corner_uvs) {
    EXPECT_GE(uv.x, 0.0);
    EXPECT_LE(uv.x, 1.0);
    EXPECT_GE(uv.y, 0.0);
    EXPECT_LE(uv.y, 1.0);
  }
}

TEST(BoxProjection, EmptySoupIsAnError) {
  Soup empty;
  try {
    box_projection(empty);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::no_triangles);
  }
}

}  // namespace
}  // namespace soupuv::baseline
