// The Krylov solve's coarse correction (charge_coarse.h) against its slow
// twin: the approximate coarse operator A~ P y against the dense A P y of
// eq. 5, and the preconditioner's effect on the solve (fewer iterations,
// the same direct-summation accuracy).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <random>

#include "field/charge_coarse.h"
#include "field/collocation.h"
#include "soupuv/field/direct.h"
#include "soupuv/field/field.h"
#include "soupuv/field/sources.h"
#include "test_size.h"
#include "testing/shapes.h"

using namespace soupuv;
using namespace soupuv::field;

TEST(CoarseCorrection, CoarseOperatorMatchesTheDenseMatrix) {
  // A noisy soup: overlapping neighbours are where the near part matters.
  Soup soup = shapes::to_soup(shapes::torus_with(1.0, 0.5, 3200), 1e-3, 1);
  SourceGeometry src = make_sources(soup.positions, soup.triangles, 4);
  const size_t n = src.size();
  FmmOptions fo;
  fo.order = 6;
  fo.leaf_size = 32;
  fo.threads = 1;
  CollocationOperator A(src, fo);
  const auto blocks = A.fmm().source_blocks(64);
  ASSERT_GT(blocks.size(), 20u);
  LeafBlockPreconditioner B(A, blocks, 1);
  CoarseCorrection C(A, src, blocks, B, 1);
  EXPECT_EQ(C.coarse_size(), blocks.size());
  // A smooth and a rough coarse vector.
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.5, 1.5);
  for (bool rough : {false, true}) {
    Eigen::VectorXd y(blocks.size());
    std::vector<double> q(n, 0.0);
    for (size_t b = 0; b < blocks.size(); ++b) {
      y[b] = rough ? u(rng) : 1.0;
      double area = 0;
      for (uint32_t j : blocks[b]) area += src.area[j];
      for (uint32_t j : blocks[b]) q[j] = y[b] * src.area[j] / area;
    }
    std::vector<double> fast, ref(n, 0.0);
    C.coarse_operator(y, fast);
    for (size_t i = 0; i < n; ++i)
      for (size_t j = 0; j < n; ++j) ref[i] += unit_potential(src, j, src.centroid[i]) * q[j];
    double worst = 0;
    for (size_t i = 0; i < n; ++i) worst = std::max(worst, std::fabs(fast[i] / ref[i] - 1));
    std::printf("coarse operator (%s) max rel error %.2e over %zu blocks, %.1f near blocks per row\n",
                rough ? "rough" : "smooth", worst, blocks.size(), double(C.near_entries()) / n);
    // Far blocks are monopoles (first-order Taylor at the rows): a few
    // percent at most, and the correction only needs the smooth part.
    EXPECT_LT(worst, 0.02);
  }
}

TEST(CoarseCorrection, CutsKrylovIterationsAtTheSameAccuracy) {
  // Plain block-Jacobi, + the coarse correction, + the blocks' overlap (the
  // default): each step must cut the iterations and keep the accuracy.
  // Iteration counts at this size (at 3,200 the coarse step saves less than
  // a third): not run reduced; CoarseOperatorMatchesTheDenseMatrix walks the
  // coarse correction's code under the sanitizers.
  SOUPUV_SKIP_IF_REDUCED("iteration counts of three solves at 6,400 triangles");
  const int triangles = 6400;
  Soup soup = shapes::to_soup(shapes::torus_with(1.0, 0.5, triangles), 1e-3, 1);
  ChargeOptions o;
  o.tolerance = 1e-6;
  o.threads = 1;
  o.verify_direct_max = 10000;  // verified by direct summation
  ChargeResult full = solve_charges(soup, o);
  o.krylov_overlap_ratio = 0;
  ChargeResult coarse = solve_charges(soup, o);
  o.krylov_coarse_correction = false;
  ChargeResult plain = solve_charges(soup, o);
  std::printf("noisy torus %d: iterations (true error) block-Jacobi %d (%.2e), + coarse %d (%.2e), + overlap %d "
              "(%.2e)\n",
              triangles, plain.iterations, plain.max_rel_potential_error, coarse.iterations, coarse.max_rel_potential_error,
              full.iterations, full.max_rel_potential_error);
  for (const ChargeResult* r : {&full, &coarse, &plain}) {
    EXPECT_EQ(r->verified_by, "direct");
    EXPECT_TRUE(r->converged);
  }
  EXPECT_LE(coarse.iterations * 3, plain.iterations * 2);  // at least a third fewer
  EXPECT_LT(full.iterations, coarse.iterations);
}
