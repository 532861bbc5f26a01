// Fmm::segment_crosses (the tracer's check of grown steps) against a test of
// every triangle, on a noisy torus soup.
#include <gtest/gtest.h>

#include <random>

#include "soupuv/field/fmm.h"
#include "soupuv/field/sources.h"
#include "soupuv/field/triangle_integrals.h"
#include "testing/shapes.h"
#include "soupuv/geometry/segment_triangle.h"

using namespace soupuv;
using namespace soupuv::field;

TEST(FmmSegment, AgreesWithEveryTriangleTest) {
  const Soup soup = shapes::to_soup(shapes::torus_with(1.0, 0.5, 3200), 1e-3, 7);
  const SourceGeometry src = make_sources(soup.positions, soup.triangles, 4);
  const Fmm fmm(src, FmmOptions{});
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0), angle(0.0, 6.283185307179586);
  size_t crossing = 0, clear = 0;
  for (int s = 0; s < 3000; ++s) {
    // Segments from near the surface (heights -0.05 .. 0.05 off the tube),
    // of lengths 0.001 .. 0.3 in random directions: many cross, many not.
    const double phi = angle(rng), psi = angle(rng), h = 0.05 * u(rng);
    const double rho = 1.0 + (0.5 + h) * std::cos(psi);
    const Vec3 a{rho * std::cos(phi), rho * std::sin(phi), (0.5 + h) * std::sin(psi)};
    const Vec3 dir = normalized(Vec3{u(rng), u(rng), u(rng)});
    const double len = 0.001 * std::pow(300.0, 0.5 * (u(rng) + 1.0));
    const Vec3 b = a + len * dir;
    bool expected = false;
    for (size_t j = 0; j < src.size() && !expected; ++j)
      expected = geometry::segment_crosses_triangle(a, b, src.a[j], src.b[j], src.c[j]);
    ASSERT_EQ(fmm.segment_crosses(a, b), expected) << "segment " << s;
    (expected ? crossing : clear)++;
  }
  EXPECT_GT(crossing, 300u);
  EXPECT_GT(clear, 300u);
}
