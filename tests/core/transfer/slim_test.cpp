// SLIM (transfer/slim.h): the energy falls, no triangle flips, and a caller's
// stop_after ends the solve where it says.
#include <gtest/gtest.h>

#include <random>

#include <Eigen/Dense>

#include "transfer/slim.h"

using namespace soupuv;
using namespace soupuv::transfer::detail;

namespace {

// A flat n x n grid of unit squares (two triangles each) as rest shapes,
// started from the grid squashed to a tenth of its height and jittered:
// every triangle positive, all of them far from their rest shapes.
struct SquashedGrid {
  std::vector<std::array<uint32_t, 3>> triangles;
  std::vector<RestTriangle> rest;
  std::vector<Vec2> uv;
};

SquashedGrid squashed_grid(int n) {
  SquashedGrid g;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> jitter(-0.05, 0.05);
  for (int y = 0; y <= n; ++y)
    for (int x = 0; x <= n; ++x) g.uv.push_back({x + jitter(rng), 0.1 * (y + jitter(rng))});
  auto id = [n](int x, int y) { return uint32_t(y * (n + 1) + x); };
  auto at = [](int x, int y) { return Vec3{double(x), double(y), 0}; };
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      g.triangles.push_back({id(x, y), id(x + 1, y), id(x + 1, y + 1)});
      g.rest.push_back(rest_triangle(at(x, y), at(x + 1, y), at(x + 1, y + 1), 1.0, 1.0));
      g.triangles.push_back({id(x, y), id(x + 1, y + 1), id(x, y + 1)});
      g.rest.push_back(rest_triangle(at(x, y), at(x + 1, y + 1), at(x, y + 1), 1.0, 1.0));
    }
  return g;
}

bool all_positive(const SquashedGrid& g) {
  for (const auto& t : g.triangles)
    if (!(cross(g.uv[t[1]] - g.uv[t[0]], g.uv[t[2]] - g.uv[t[0]]) > 0)) return false;
  return true;
}

}  // namespace

TEST(Slim, LowersTheEnergyWithoutFlippingATriangle) {
  SquashedGrid g = squashed_grid(8);
  ASSERT_TRUE(all_positive(g));
  const std::vector<uint8_t> fixed(g.uv.size(), 0);
  SlimOptions o;
  o.max_iterations = 20;
  const SlimResult r = slim_relax(g.triangles, g.rest, fixed, g.uv, o);
  ASSERT_TRUE(r.started);
  EXPECT_LT(r.energy_after, 0.2 * r.energy_before);
  // The symmetric Dirichlet energy is at least 4 x area, met at isometries.
  double rest_area = 0;
  for (const auto& t : g.rest) rest_area += t.area;
  EXPECT_LT(r.energy_after, 4.4 * rest_area);
  EXPECT_NEAR(r.energy_after, mesh_energy(g.triangles, g.rest, g.uv), 1e-9 * r.energy_after);
  EXPECT_TRUE(all_positive(g));
}

TEST(Slim, StopAfterEndsTheSolveAtTheIterationItSays) {
  SquashedGrid full = squashed_grid(8), stopped = full;
  const std::vector<uint8_t> fixed(full.uv.size(), 0);
  SlimOptions o;
  o.max_iterations = 10;
  o.min_relative_decrease = 0;
  const SlimResult all = slim_relax(full.triangles, full.rest, fixed, full.uv, o);
  std::vector<int> seen;
  o.stop_after = [&](int iterations, const std::vector<Vec2>& uv) {
    seen.push_back(iterations);
    EXPECT_EQ(uv.size(), stopped.uv.size());
    return iterations == 3;
  };
  const SlimResult three = slim_relax(stopped.triangles, stopped.rest, fixed, stopped.uv, o);
  EXPECT_EQ(seen, (std::vector<int>{1, 2, 3}));
  EXPECT_EQ(three.iterations, 3);
  EXPECT_GT(all.iterations, 3);
  // Stopped early, it is where the full solve was after three iterations:
  // higher than the end, lower than the start.
  EXPECT_GT(three.energy_after, all.energy_after);
  EXPECT_LT(three.energy_after, three.energy_before);
  EXPECT_NEAR(three.energy_after, mesh_energy(stopped.triangles, stopped.rest, stopped.uv), 1e-9 * three.energy_after);
}

TEST(Slim, LocalTargetIsTheSingularValueDecompositionsRotationAndWeights) {
  // Against Eigen's SVD, on Jacobians of every kind with det > 0: near
  // rotations, strong stretch, shear, near-degenerate, conformal (s1 = s2).
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> entry(-3, 3);
  auto w = [](double s) { return (1 + s) * (1 + s * s) / (s * s * s); };
  std::vector<Jacobian> cases = {{1, 0, 0, 1}, {2, 0, 0, 2}, {0, -1, 1, 0}, {3, 0, 0, 0.01}, {1, 5, 0, 1},
                                 {0.6, -0.8, 0.8, 0.6}};
  while (cases.size() < 2000) {
    const Jacobian J{entry(rng), entry(rng), entry(rng), entry(rng)};
    if (J.det() > 1e-3) cases.push_back(J);
  }
  for (const Jacobian& J : cases) {
    Eigen::Matrix2d A;
    A << J.j00, J.j01, J.j10, J.j11;
    const Eigen::JacobiSVD<Eigen::Matrix2d> svd(A, Eigen::ComputeFullU | Eigen::ComputeFullV);
    const Eigen::Vector2d s = svd.singularValues();
    const Eigen::Matrix2d R = svd.matrixU() * svd.matrixV().transpose();
    const Eigen::Matrix2d M = svd.matrixU() * Eigen::Vector2d(w(s[0]), w(s[1])).asDiagonal() * svd.matrixU().transpose();
    const LocalTarget t = local_target(J);
    const double scale = M.cwiseAbs().maxCoeff();
    EXPECT_NEAR(t.r00, R(0, 0), 1e-9);
    EXPECT_NEAR(t.r01, R(0, 1), 1e-9);
    EXPECT_NEAR(t.r10, R(1, 0), 1e-9);
    EXPECT_NEAR(t.r11, R(1, 1), 1e-9);
    EXPECT_NEAR(t.m00, M(0, 0), 1e-9 * scale) << J.j00 << " " << J.j01 << " " << J.j10 << " " << J.j11;
    EXPECT_NEAR(t.m01, M(0, 1), 1e-9 * scale);
    EXPECT_NEAR(t.m11, M(1, 1), 1e-9 * scale);
  }
}
