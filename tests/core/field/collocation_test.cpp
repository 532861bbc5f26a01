// The Krylov solve's building blocks against their slow twins: GMRES against
// a dense LU solve, the collocation operator (precomputed near matrix + FMM
// far field, full and cheap order) against the dense matrix of eq. 5, and the
// preconditioner's block partition.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <random>

#include "field/collocation.h"
#include "field/gmres.h"
#include "soupuv/field/sources.h"
#include "testing/shapes.h"

using namespace soupuv;
using namespace soupuv::field;

TEST(Gmres, MatchesDenseLuWithRestartsAndPreconditioner) {
  const int n = 80;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  Eigen::MatrixXd A(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) A(i, j) = u(rng) + (i == j ? 4.0 + i * 0.1 : 0.0);
  std::vector<double> b(n);
  for (double& v : b) v = u(rng);
  Eigen::VectorXd ref = A.partialPivLu().solve(Eigen::Map<Eigen::VectorXd>(b.data(), n));
  LinearMap apply_A = [&](const std::vector<double>& v, std::vector<double>& out) {
    Eigen::VectorXd r = A * Eigen::Map<const Eigen::VectorXd>(v.data(), n);
    out.assign(r.data(), r.data() + n);
  };
  LinearMap identity = [](const std::vector<double>& v, std::vector<double>& out) { out = v; };
  LinearMap jacobi = [&](const std::vector<double>& v, std::vector<double>& out) {
    out.resize(n);
    for (int i = 0; i < n; ++i) out[i] = v[i] / A(i, i);
  };
  for (const LinearMap* M : {&identity, &jacobi}) {
    GmresOptions o;
    o.rtol = 1e-10;
    o.restart = 7;  // forces several restarts
    o.max_iterations = 2000;
    GmresResult r = gmres(apply_A, *M, b, o);
    double err = 0;
    for (int i = 0; i < n; ++i) err = std::max(err, std::fabs(r.x[i] - ref[i]));
    EXPECT_LT(err, 1e-8) << "iterations " << r.iterations;
    EXPECT_LE(r.estimate, 1e-10);
  }
  // A restart-free run stops at the tolerance it was given, not earlier.
  GmresOptions loose;
  loose.rtol = 1e-2;
  GmresResult r = gmres(apply_A, identity, b, loose);
  EXPECT_LE(r.estimate, 1e-2);
  EXPECT_GT(r.estimate, 1e-12);
}

// x -> x shifted by one place, cyclically (n x n), and the identity.
LinearMap cyclic_shift(int n) {
  return [n](const std::vector<double>& v, std::vector<double>& out) {
    out.resize(n);
    for (int i = 0; i < n; ++i) out[(i + 1) % n] = v[i];
  };
}
LinearMap identity_map() {
  return [](const std::vector<double>& v, std::vector<double>& out) { out = v; };
}
// e1: the right-hand side on which GMRES makes no progress on the shift.
std::vector<double> first_unit_vector(int n) {
  std::vector<double> b(n, 0.0);
  b[0] = 1;
  return b;
}
// GMRES asked for 1e-8 with restarts of `restart` vectors.
GmresOptions tight_options(int restart) {
  GmresOptions o;
  o.rtol = 1e-8;
  o.restart = restart;
  return o;
}
// A diagonal system with eigenvalues spread evenly over [1, largest]:
// GMRES converges slowly but steadily on it.
LinearMap spread_diagonal(int n, double largest) {
  return [n, largest](const std::vector<double>& v, std::vector<double>& out) {
    out.resize(n);
    for (int i = 0; i < n; ++i) out[i] = (1.0 + (largest - 1.0) * i / (n - 1)) * v[i];
  };
}

// GMRES(m) on the cyclic shift makes no progress until m reaches n (the
// Krylov space of e1 holds e1..e_m, none of which reduces the residual):
// the stall rule stops after one cycle and says so; without it the solve
// spends every iteration it is given.
TEST(Gmres, StopsWhenARestartCycleStalls) {
  const int n = 50;
  const LinearMap shift = cyclic_shift(n), identity = identity_map();
  const std::vector<double> b = first_unit_vector(n);
  GmresOptions o = tight_options(10);
  o.max_iterations = 200;
  const GmresResult stalled = gmres(shift, identity, b, o);
  EXPECT_TRUE(stalled.stalled);
  EXPECT_LE(stalled.iterations, o.restart + 1);
  o.stall_ratio = 1;
  const GmresResult spent = gmres(shift, identity, b, o);
  EXPECT_FALSE(spent.stalled);
  EXPECT_GE(spent.iterations, o.max_iterations);
}

// The in-cycle test stops a cycle that is flat from its start after
// stall_window iterations instead of its restart length; on a system that
// converges steadily it never fires.
TEST(Gmres, StopsInsideACycleThatStalls) {
  const int n = 50;
  const LinearMap shift = cyclic_shift(n), identity = identity_map();
  const std::vector<double> b = first_unit_vector(n);
  GmresOptions o = tight_options(40);
  o.stall_window = 10;
  const GmresResult stalled = gmres(shift, identity, b, o);
  EXPECT_TRUE(stalled.stalled);
  EXPECT_EQ(stalled.iterations, o.stall_window);

  // A diagonal system with eigenvalues spread over [1, 100]: slow but
  // steady, each iteration gains a little; the window must not mistake it
  // for a stall.
  const LinearMap spread = spread_diagonal(n, 100.0);
  std::vector<double> ones(n, 1.0);
  o.restart = 60;
  o.stall_window = 20;
  const GmresResult steady = gmres(spread, identity, ones, o);
  EXPECT_FALSE(steady.stalled);
  EXPECT_LE(steady.estimate, o.rtol);
}

// The budget test stops a solve that cannot reach its goal within its
// budget at its recent rate, and only such a solve: a flat one stops after
// one window; a steady one whose rate reaches the goal in its budget runs to
// convergence; the same steady solve given too small a budget stops early
// rather than spend it.
TEST(Gmres, StopsWhenItsRateCannotReachTheGoalInItsBudget) {
  const int n = 50;
  const LinearMap shift = cyclic_shift(n), identity = identity_map();
  const std::vector<double> b = first_unit_vector(n);
  GmresOptions o = tight_options(40);
  o.max_iterations = 30;
  o.reach_window = 4;
  const GmresResult flat = gmres(shift, identity, b, o);
  EXPECT_TRUE(flat.out_of_reach);
  EXPECT_EQ(flat.iterations, o.reach_window);

  const LinearMap spread = spread_diagonal(n, 10.0);
  std::vector<double> ones(n, 1.0);
  o.max_iterations = 60;
  const GmresResult steady = gmres(spread, identity, ones, o);
  EXPECT_FALSE(steady.out_of_reach);
  EXPECT_LE(steady.estimate, o.rtol);
  o.reach_window = 0;
  const int needed = gmres(spread, identity, ones, o).iterations;
  EXPECT_EQ(steady.iterations, needed);  // the test cost nothing where it could reach

  o.reach_window = 4;
  o.max_iterations = needed / 3;
  const GmresResult short_budget = gmres(spread, identity, ones, o);
  EXPECT_TRUE(short_budget.out_of_reach);
  EXPECT_LT(short_budget.iterations, o.max_iterations);
}

TEST(Gmres, StopsOnTheMaxNormOfTheTrueResidual) {
  // The max-norm residual GMRES forms from the Arnoldi relation (no
  // mat-vec) must be the true one: after the stop, max |b - A x| by a dense
  // product is at or below the target and equals the reported max_norm,
  // with and without restarts.
  const int n = 120;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  Eigen::MatrixXd A(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) A(i, j) = u(rng) + (i == j ? 12.0 + i * 0.05 : 0.0);
  std::vector<double> b(n);
  for (double& v : b) v = u(rng);
  LinearMap apply_A = [&](const std::vector<double>& v, std::vector<double>& out) {
    Eigen::VectorXd r = A * Eigen::Map<const Eigen::VectorXd>(v.data(), n);
    out.assign(r.data(), r.data() + n);
  };
  LinearMap identity = [](const std::vector<double>& v, std::vector<double>& out) { out = v; };
  auto true_max = [&](const std::vector<double>& x) {
    std::vector<double> ax;
    apply_A(x, ax);
    double worst = 0;
    for (int i = 0; i < n; ++i) worst = std::max(worst, std::fabs(b[i] - ax[i]));
    return worst;
  };
  for (int restart : {200, 9}) {
    GmresOptions o;
    o.rtol = 0;
    o.max_norm_target = 1e-7;
    o.restart = restart;
    o.max_iterations = 2000;
    GmresResult r = gmres(apply_A, identity, b, o);
    EXPECT_LE(true_max(r.x), 1e-7 * (1 + 1e-6)) << "restart " << restart;
    EXPECT_NEAR(r.max_norm, true_max(r.x), 1e-12) << "restart " << restart;
    EXPECT_LT(r.iterations, 2000);
  }
}

TEST(Collocation, FullAndCheapOperatorsMatchTheDenseMatrix) {
  Soup soup = shapes::to_soup(shapes::torus_with(1.0, 0.5, 1800));
  SourceGeometry src = make_sources(soup.positions, soup.triangles, 4);
  const size_t n = src.size();
  std::vector<double> q(n);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0.5, 1.5);
  for (double& v : q) v = u(rng) / n;
  std::vector<double> ref(n, 0.0);
  for (size_t i = 0; i < n; ++i)
    for (size_t j = 0; j < n; ++j) ref[i] += unit_potential(src, j, src.centroid[i]) * q[j];
  FmmOptions fo;
  fo.order = 8;
  fo.theta = 0.5;
  fo.leaf_size = 16;  // small leaves so that most pairs go through the far field
  CollocationOperator A(src, fo, 4);
  EXPECT_LT(A.near_entries(), n * n / 2);
  std::vector<double> full, cheap;
  A.apply(q, full, CollocationOperator::Accuracy::full);
  A.apply(q, cheap, CollocationOperator::Accuracy::cheap);
  double err_full = 0, err_cheap = 0;
  for (size_t i = 0; i < n; ++i) {
    err_full = std::max(err_full, std::fabs(full[i] / ref[i] - 1));
    err_cheap = std::max(err_cheap, std::fabs(cheap[i] / ref[i] - 1));
  }
  std::printf("collocation operator max rel error: p=8 %.2e, p=4 %.2e (near entries per row %.0f)\n", err_full,
              err_cheap, double(A.near_entries()) / n);
  EXPECT_LT(err_full, 1e-6);
  EXPECT_LT(err_cheap, 1e-3);
  EXPECT_GT(err_cheap, err_full);  // the cheap far field really is a different (coarser) one
}

TEST(Fmm, SourceBlocksPartitionTheTriangles) {
  Soup soup = shapes::to_soup(shapes::torus_with(1.0, 0.5, 3200));
  SourceGeometry src = make_sources(soup.positions, soup.triangles, 4);
  FmmOptions fo;
  fo.leaf_size = 16;
  Fmm fmm(src, fo, src.centroid);
  for (int max_count : {16, 100, 1000}) {
    auto blocks = fmm.source_blocks(max_count);
    std::vector<int> seen(src.size(), 0);
    size_t largest = 0;
    for (const auto& b : blocks) {
      largest = std::max(largest, b.size());
      for (uint32_t j : b) ++seen[j];
    }
    EXPECT_TRUE(std::all_of(seen.begin(), seen.end(), [](int c) { return c == 1; }));
    EXPECT_LE(largest, static_cast<size_t>(max_count));
    EXPECT_GT(largest, static_cast<size_t>(max_count) / 16);  // the largest cells that fit, not leaves
  }
}
