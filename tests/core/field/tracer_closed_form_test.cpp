// The tracer's closed-form triangle field (one solid-angle atan2, frame
// precomputed) against triangle_integrals, its slow twin: random triangles,
// points anywhere, in the plane inside the triangle, just above and below
// it, and next to an edge.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "field/tracer_closed_form.h"
#include "soupuv/field/triangle_integrals.h"

using namespace soupuv;
using namespace soupuv::field;

TEST(TracerClosedForm, MatchesTriangleIntegrals) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1), unit(0, 1), expo(-7, 0);
  double worst[4] = {0, 0, 0, 0};
  for (int it = 0; it < 40000; ++it) {
    const Vec3 a{u(rng), u(rng), u(rng)}, b{u(rng), u(rng), u(rng)}, c{u(rng), u(rng), u(rng)};
    const Vec3 n = normalized(cross(b - a, c - a));
    double s = unit(rng), t = unit(rng);
    if (s + t > 1) s = 1 - s, t = 1 - t;
    const Vec3 inside = a + s * (b - a) + t * (c - a);
    const double h = std::pow(10.0, expo(rng));
    const int mode = it % 4;
    Vec3 x;
    if (mode == 0) x = {2 * u(rng), 2 * u(rng), 2 * u(rng)};
    else if (mode == 1) x = inside;                               // in the plane: normal part 0
    else if (mode == 2) x = inside + (it % 8 < 4 ? h : -h) * n;   // just above / below
    else x = a + s * (b - a) + h * normalized(cross(n, b - a));   // next to edge ab, in the plane
    const Vec3 ref = triangle_integrals(a, b, c, x).field;
    const Vec3 got = tracer::closed_form_field(tracer::triangle_frame(a, b, c), x);
    worst[mode] = std::max(worst[mode], norm(got - ref) / norm(ref));
  }
  std::printf("closed form vs triangle_integrals, max rel difference: anywhere %.1e, in plane %.1e, "
              "above/below %.1e, next to an edge %.1e\n",
              worst[0], worst[1], worst[2], worst[3]);
  for (double w : worst) EXPECT_LT(w, 1e-9);
}

TEST(TracerClosedForm, DegenerateTriangleHasNoField) {
  const Vec3 a{0, 0, 0}, b{1, 0, 0}, c{2, 0, 0};
  EXPECT_TRUE(tracer::triangle_frame(a, b, c).degenerate);
  const Vec3 f = tracer::closed_form_field(tracer::triangle_frame(a, b, c), {0.5, 1, 0});
  EXPECT_EQ(norm(f), 0.0);
}
