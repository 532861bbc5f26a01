// TracerField (the tracer's batched evaluator) against its slow twins: direct
// summation over every triangle and the generic Fmm::evaluate, at points from
// on the surface to far away, evaluated one at a time and in leaf batches.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cmath>
#include <limits>
#include <random>

#include "soupuv/field/direct.h"
#include "soupuv/field/field.h"
#include "soupuv/field/fmm.h"
#include "soupuv/field/tracer_field.h"
#include "testing/shapes.h"

using namespace soupuv;
using namespace soupuv::field;

namespace {

struct Case {
  Soup soup;
  ChargeResult charges;
  SourceGeometry src;
  std::vector<Vec3> points;   // sample points, outside the torus tube
  std::vector<Vec3> direct;   // direct-summation field at them
};

// A charged 1,800-triangle torus and points at heights 1e-5 .. 3 above random
// points on the surface (outside the tube), plus two beyond the region.
const Case& torus_case() {
  static const Case c = [] {
    Case k;
    k.soup = shapes::to_soup(shapes::torus_with(1.0, 0.5, 1800));
    ChargeOptions co;
    co.tolerance = 1e-6;
    k.charges = solve_charges(k.soup, co);
    k.src = make_sources(k.charges.positions, k.charges.triangles, k.charges.quadrature_degree);
    std::mt19937 rng(7);
    std::uniform_int_distribution<size_t> tri(0, k.soup.triangles.size() - 1);
    std::uniform_real_distribution<double> expo(-4.0, 1.0);
    for (int i = 0; i < 300; ++i) {
      size_t t = tri(rng);
      Vec3 v = k.soup.corner(t, i % 3);
      Vec3 g = (k.soup.corner(t, 0) + k.soup.corner(t, 1) + k.soup.corner(t, 2)) / 3.0;
      Vec3 base = v + 0.2 * (g - v);
      // Away from the tube's centre circle: outside the closed torus, where
      // the field does not vanish (inside, a relative error means nothing).
      const double rho = std::hypot(base.x, base.y);
      Vec3 out = normalized(base - Vec3{base.x / rho, base.y / rho, 0.0});
      Vec3 x = base + std::pow(10.0, expo(rng)) * out;
      k.points.push_back(x);
    }
    k.points.push_back({40, 0, 0});
    k.points.push_back({0, -3, 25});
    direct_sum(k.src, k.charges.charges, k.points, nullptr, &k.direct);
    return k;
  }();
  return c;
}

// The tests' FMM: leaves of 8 triangles, so the torus has many cells.
FmmOptions small_leaves(int order, double theta) {
  FmmOptions fo;
  fo.order = order;
  fo.theta = theta;
  fo.leaf_size = 8;
  return fo;
}

// The worst field error relative to direct summation over the case's
// points, one point at a time; `near` (when given) counts the points that
// have a near triangle.
double worst_error(const Case& k, TracerField& tf, size_t* near = nullptr) {
  double worst = 0;
  for (size_t i = 0; i < k.points.size(); ++i) {
    const int leaf = tf.locate(k.points[i]);
    tf.prepare({leaf});
    Vec3 E{0, 0, 0};
    double nearest = 0;
    tf.field(leaf, &k.points[i], 1, &E, near ? &nearest : nullptr);
    worst = std::max(worst, norm(E - k.direct[i]) / norm(k.direct[i]));
    if (near && nearest < std::numeric_limits<double>::infinity()) ++*near;
  }
  return worst;
}

Box3 region_around(const Case& k, double half) {
  Box3 r;
  r.add({-half, -half, -half});
  r.add({half, half, half});
  (void)k;
  return r;
}

}  // namespace

TEST(TracerField, MatchesDirectSummationToTheFmmAccuracy) {
  const Case& k = torus_case();
  Fmm fmm(k.src, small_leaves(8, 0.4), region_around(k, 10));
  TracerField tf(fmm, k.charges.charges);
  size_t near = 0;
  const double worst = worst_error(k, tf, &near);
  std::printf("tracer field vs direct, p=8 theta=0.4: max rel error %.2e, %zu of %zu points near a triangle\n", worst,
              near, k.points.size());
  EXPECT_LT(worst, 1e-4);
  // The samples must cover both regimes: next to the surface and far from it.
  EXPECT_GT(near, k.points.size() / 5);
  EXPECT_LT(near, k.points.size() * 9 / 10);
}

TEST(TracerField, AgreesWithFmmEvaluateAndBatchesAgreeWithSinglePoints) {
  const Case& k = torus_case();
  Fmm fmm(k.src, small_leaves(6, 0.5), region_around(k, 10));
  fmm.set_charges(k.charges.charges);
  // Fmm::evaluate expands every pair at the full order.
  TracerField tf(fmm, k.charges.charges, 2, TracerField::M2lOrder::full);
  // Group the points by leaf, as the tracer does.
  std::vector<int> leaf(k.points.size());
  for (size_t i = 0; i < k.points.size(); ++i) leaf[i] = tf.locate(k.points[i], i > 0 ? leaf[i - 1] : -1);
  tf.prepare(leaf);
  double worst_fmm = 0, worst_batch = 0;
  for (size_t i = 0; i < k.points.size(); ++i) {
    Vec3 Ef{0, 0, 0}, Et{0, 0, 0};
    double nf = 0, nt = 0;
    fmm.evaluate(k.points[i], nullptr, &Ef, &nf);
    tf.field(leaf[i], &k.points[i], 1, &Et, &nt);
    // Same expansions and near lists; only the split band (degree-6 on four
    // children instead of the closed form) may differ, below the model's error.
    worst_fmm = std::max(worst_fmm, norm(Et - Ef) / norm(Ef));
    EXPECT_EQ(nf, nt) << "nearest near triangle differs at point " << i;
    // All points of the same leaf at once.
    std::vector<Vec3> xs, Es;
    for (size_t j = 0; j < k.points.size(); ++j)
      if (leaf[j] == leaf[i]) xs.push_back(k.points[j]);
    Es.assign(xs.size(), Vec3{0, 0, 0});
    tf.field(leaf[i], xs.data(), static_cast<int>(xs.size()), Es.data(), nullptr);
    for (size_t j = 0; j < xs.size(); ++j)
      if (norm2(xs[j] - k.points[i]) == 0) worst_batch = std::max(worst_batch, norm(Es[j] - Et) / norm(Et));
  }
  std::printf("tracer field vs Fmm::evaluate: max rel difference %.2e; batch vs single %.2e\n", worst_fmm, worst_batch);
  EXPECT_LT(worst_fmm, 1e-5);
  EXPECT_LT(worst_batch, 1e-13);
  EXPECT_GT(tf.expansions(), 0u);
  EXPECT_LT(tf.expansions(), fmm.stats().target_cells);  // lazily: not every cell
}

// Each M2L pair at the order its separation needs: the field against direct
// summation as accurate as with every pair at the full order, for fewer
// multiply-adds. Points one at a time, as in the test above.
TEST(TracerField, PerPairOrdersKeepTheAccuracyForFewerTerms) {
  const Case& k = torus_case();
  Fmm fmm(k.src, small_leaves(7, 0.45), region_around(k, 10));
  double worst[2] = {0, 0};
  size_t terms[2] = {0, 0}, ops[2] = {0, 0};
  const TracerField::M2lOrder orders[2] = {TracerField::M2lOrder::full, TracerField::M2lOrder::per_pair};
  for (int v = 0; v < 2; ++v) {
    TracerField tf(fmm, k.charges.charges, 2, orders[v]);
    worst[v] = worst_error(k, tf);
    terms[v] = tf.m2l_terms();
    ops[v] = tf.m2l_operations();
  }
  std::printf("field vs direct, p=7 theta=0.45: full order %.2e (%zu terms), per pair %.2e (%zu terms)\n", worst[0],
              terms[0], worst[1], terms[1]);
  // No less accurate than every pair at the full order (10 %: the errors of
  // different truncations do not cancel alike at the worst point).
  EXPECT_LT(worst[1], 1.1 * worst[0]);
  EXPECT_EQ(ops[0], ops[1]);  // the same pairs
  EXPECT_LT(terms[1], terms[0]);
}

// The order rule: the full order at and beyond the acceptance limit, and
// otherwise the lowest q (from 2) with rho^q <= theta^(p + 1).
TEST(TracerField, PerPairOrderIsTheLowestThatKeepsTheWorstPairsBound) {
  const double theta = 0.45;
  for (int p : {1, 2, 5, 7, 10}) {
    EXPECT_EQ(TracerField::m2l_order_for(theta, theta, p), p);
    EXPECT_EQ(TracerField::m2l_order_for(0.9, theta, p), p);
    EXPECT_EQ(TracerField::m2l_order_for(0.0, theta, p), std::min(2, p));
    int last = 0;
    for (double rho = 1e-3; rho < theta; rho += 1e-3) {
      const int q = TracerField::m2l_order_for(rho, theta, p);
      EXPECT_GE(q, last) << "not monotone at rho " << rho;
      last = q;
      EXPECT_LE(q, p);
      if (q < p) {
        EXPECT_LE(std::pow(rho, q), std::pow(theta, p + 1) * (1 + 1e-9)) << "rho " << rho << " q " << q;
      }
      if (q > std::min(2, p)) {
        EXPECT_GT(std::pow(rho, q - 1), std::pow(theta, p + 1)) << "rho " << rho << " q " << q;
      }
    }
  }
}
