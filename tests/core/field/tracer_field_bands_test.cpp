// TracerField at points on and next to the boundaries of its near bands
// (1.55, 2.25 and 4 triangle radii from a triangle's centroid), where the
// float kernel's candidate test (with its slack) meets the double band
// decisions: every point must agree with the slow twin Fmm::evaluate to the
// bands' quadrature error and find the same nearest near triangle.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "soupuv/field/field.h"
#include "soupuv/field/fmm.h"
#include "soupuv/field/tracer_field.h"
#include "testing/shapes.h"

using namespace soupuv;
using namespace soupuv::field;

TEST(TracerFieldBands, PointsAtBandBoundariesAgreeWithFmmEvaluate) {
  const Soup soup = shapes::to_soup(shapes::torus_with(1.0, 0.5, 800));
  ChargeOptions co;
  co.tolerance = 1e-6;
  const ChargeResult charges = solve_charges(soup, co);
  const SourceGeometry src = make_sources(charges.positions, charges.triangles, charges.quadrature_degree);
  FmmOptions fo;
  fo.order = 6;
  fo.theta = 0.5;
  fo.leaf_size = 8;
  Box3 region;
  region.add({-10, -10, -10});
  region.add({10, 10, 10});
  Fmm fmm(src, fo, region);
  fmm.set_charges(charges.charges);
  // The same expansions as Fmm::evaluate (every pair at the full order).
  TracerField tf(fmm, charges.charges, 1, TracerField::M2lOrder::full);

  // Points at each band radius of a triangle's centroid, exactly and moved by
  // 1e-9 to 2e-3 of it (the kernel's slack is 1e-4 in r2), outwards from the
  // tube (outside the closed torus, where the field does not vanish).
  const double factors[] = {1.55, 2.25, 4.0};
  const double moves[] = {1.0, 1.0 - 1e-9, 1.0 + 1e-9, 1.0 - 5e-4, 1.0 + 5e-4, 1.0 - 2e-3, 1.0 + 2e-3};
  std::vector<Vec3> points;
  for (size_t j = 0; j < src.size(); j += 37) {
    const Vec3 c = src.centroid[j];
    const double rho = std::hypot(c.x, c.y);
    const Vec3 out = normalized(c - Vec3{c.x / rho, c.y / rho, 0.0});
    const Vec3 along = normalized(cross(out, Vec3{0, 0, 1}) + 0.3 * cross(out, Vec3{1, 0, 0}));
    for (double f : factors)
      for (double mv : moves)
        for (double a : {0.0, 0.5}) {
          const Vec3 dir = std::cos(a) * out + std::sin(a) * normalized(along - dot(along, out) * out);
          points.push_back(c + (f * mv * src.radius[j]) * dir);
        }
  }
  double worst = 0;
  size_t near = 0;
  for (const Vec3& x : points) {
    const int leaf = tf.locate(x);
    tf.prepare({leaf});
    Vec3 Ef{0, 0, 0}, Et{0, 0, 0};
    double nf = 0, nt = 0;
    fmm.evaluate(x, nullptr, &Ef, &nf);
    tf.field(leaf, &x, 1, &Et, &nt);
    worst = std::max(worst, norm(Et - Ef) / norm(Ef));
    EXPECT_EQ(nf, nt) << "nearest near triangle differs at " << x.x << " " << x.y << " " << x.z;
    if (nt < 1e30) ++near;
  }
  std::printf("band boundaries: %zu points (%zu near a triangle), tracer field vs Fmm::evaluate max rel %.2e\n",
              points.size(), near, worst);
  // Most points are near some triangle (those 4 radii out from a small one may not be).
  EXPECT_GT(near, points.size() * 9 / 10);
  EXPECT_LT(worst, 1e-5);
}
