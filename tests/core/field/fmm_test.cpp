// FMM against direct summation (its slow twin) for several expansion orders:
// the error must shrink as p grows and be small at the orders we use.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "soupuv/field/direct.h"
#include "soupuv/field/fmm.h"
#include "soupuv/field/taylor.h"
#include "testing/shapes.h"

using namespace soupuv;
using namespace soupuv::field;

TEST(Taylor, KernelDerivativesMatchFiniteDifferences) {
  TaylorBasis basis(8);
  Vec3 R{0.7, -0.4, 1.1};
  std::vector<double> k(TaylorBasis::size_for(5));
  basis.kernel(R, 5, k.data());
  EXPECT_NEAR(k[0], 1 / norm(R), 1e-15);
  // k_{e_x}(R) = R_x / r^3 and the y-derivative of 1/|x - y| at y = 0 is the same.
  EXPECT_NEAR(k[1], R.x / std::pow(norm(R), 3), 1e-14);
  // Moments of one unit charge at s reproduce 1/|x - s| through M2P.
  Vec3 s{0.1, 0.05, -0.08};
  std::vector<double> M(basis.size(), 0.0);
  double q = 1;
  basis.p2m({0, 0, 0}, &s, &q, 1, M.data());
  double phi = 0;
  Vec3 E{0, 0, 0};
  Vec3 x = R;
  basis.m2p(M.data(), x, &phi, &E);
  EXPECT_NEAR(phi, 1 / norm(x - s), 1e-6);
  Vec3 e_exact = (x - s) / std::pow(norm(x - s), 3);
  EXPECT_LT(norm(E - e_exact), 1e-5 * norm(e_exact));
}

namespace {
struct Case {
  SourceGeometry src;
  std::vector<double> q;
  std::vector<Vec3> targets;
  std::vector<double> phi;
  std::vector<Vec3> E;
};

Case make_case() {
  Case c;
  Soup soup = shapes::to_soup(shapes::torus_with(1.0, 0.5, 1800), 1e-3, 3);
  c.src = make_sources(soup.positions, soup.triangles, 4);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.5, 1.5), box(-2, 2);
  for (size_t j = 0; j < c.src.size(); ++j) c.q.push_back(u(rng) * c.src.area[j]);
  for (size_t j = 0; j < c.src.size(); j += 3) c.targets.push_back(c.src.centroid[j]);
  for (int i = 0; i < 1000; ++i) c.targets.push_back({box(rng), box(rng), box(rng) * 0.5});
  direct_sum(c.src, c.q, c.targets, &c.phi, &c.E);
  return c;
}

std::pair<double, double> fmm_error(const Case& c, int p, double theta) {
  Box3 region;
  region.add({-2, -2, -1});
  region.add({2, 2, 1});
  Fmm fmm(c.src, FmmOptions{p, theta, 16, 0}, region);
  fmm.set_charges(c.q);
  const FmmStats& st = fmm.stats();
  std::printf("  cells: source %zu (leaves %zu) target %zu, m2l %zu, near leaf pairs %zu; build %.3fs up %.3fs m2l %.3fs down %.3fs\n",
              st.source_cells, st.source_leaves, st.target_cells, st.m2l_pairs, st.near_leaf_pairs,
              st.build_seconds, st.upward_seconds, st.m2l_seconds, st.downward_seconds);
  double max_phi = 0, max_e = 0, scale_phi = 0, scale_e = 0;
  for (size_t i = 0; i < c.targets.size(); ++i) {
    double phi = 0;
    Vec3 E{0, 0, 0};
    fmm.evaluate(c.targets[i], &phi, &E);
    EXPECT_TRUE(std::isfinite(phi) && std::isfinite(E.x)) << "p=" << p << " target " << i << " phi " << phi << " E " << E.x << " leaf " << fmm.locate(c.targets[i]);
    max_phi = std::max(max_phi, std::fabs(phi - c.phi[i]));
    max_e = std::max(max_e, norm(E - c.E[i]));
    scale_phi = std::max(scale_phi, std::fabs(c.phi[i]));
    scale_e = std::max(scale_e, norm(c.E[i]));
  }
  return {max_phi / scale_phi, max_e / scale_e};
}
TEST(Fmm, OneTriangleBuildsASmallTreeAndMatchesDirectSum) {
  // One triangle: the centroids' box has no size. The tree must still
  // end (it once split toward the point until memory ran out).
  const std::vector<Vec3> positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  const std::vector<Tri> triangles = {{0, 1, 2}};
  const SourceGeometry src = make_sources(positions, triangles, 4);
  Box3 region;
  region.add({-3, -3, -3});
  region.add({3, 3, 3});
  Fmm fmm(src, FmmOptions{8, 0.5, 16, 0}, region);
  fmm.set_charges({1.0});
  EXPECT_LT(fmm.stats().target_cells, 100000u);
  const std::vector<Vec3> targets = {{2, 2, 2}, {0.3, 0.3, 0.5}, {-2, 1, -1}};
  std::vector<double> phi;
  std::vector<Vec3> E;
  direct_sum(src, {1.0}, targets, &phi, &E);
  for (size_t i = 0; i < targets.size(); ++i) {
    double p = 0;
    Vec3 e{0, 0, 0};
    fmm.evaluate(targets[i], &p, &e);
    EXPECT_NEAR(p, phi[i], 1e-6 * std::fabs(phi[i])) << "target " << i;
  }
}

}  // namespace

TEST(Fmm, ErrorShrinksWithOrder) {
  Case c = make_case();
  double previous = 1;
  for (int p : {2, 4, 6, 8}) {
    auto [ephi, efield] = fmm_error(c, p, 0.5);
    std::printf("fmm p=%d theta=0.5: max rel potential error %.2e, field %.2e\n", p, ephi, efield);
    EXPECT_LT(ephi, previous);
    previous = ephi;
    if (p == 8) {
      EXPECT_LT(ephi, 1e-6);
      EXPECT_LT(efield, 2e-5);
    }
  }
}

TEST(Fmm, CopyForAnotherOrderMatchesAFreshBuild) {
  // Fmm(other, order) reuses other's trees and lists: it must evaluate
  // exactly as an Fmm built from scratch with that order.
  Soup soup = shapes::to_soup(shapes::torus_with(1.0, 0.5, 3200), 1e-3, 1);
  SourceGeometry src = make_sources(soup.positions, soup.triangles, 4);
  FmmOptions fo;
  fo.order = 8;
  fo.leaf_size = 32;
  fo.threads = 1;
  Fmm base(src, fo, src.centroid);
  Fmm copied(base, 5);
  fo.order = 5;
  Fmm fresh(src, fo, src.centroid);
  std::vector<double> q(src.size());
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(0.5, 1.5);
  for (double& v : q) v = u(rng);
  copied.set_charges(q);
  fresh.set_charges(q);
  base.set_charges(q);
  double worst = 0, order_gap = 0;
  for (size_t i = 0; i < src.size(); i += 7) {
    double a = 0, b = 0, c = 0;
    copied.evaluate(src.centroid[i], &a, nullptr);
    fresh.evaluate(src.centroid[i], &b, nullptr);
    base.evaluate(src.centroid[i], &c, nullptr);
    worst = std::max(worst, std::fabs(a - b) / std::fabs(b));
    order_gap = std::max(order_gap, std::fabs(a - c) / std::fabs(c));
  }
  EXPECT_LT(worst, 1e-13);
  EXPECT_GT(order_gap, 1e-9);  // it really is the lower order, not the base's expansions
}

TEST(Fmm, ParallelTreeBuildMatchesTheSerialOne) {
  // With threads > 1 the target subtrees below a frontier are built in
  // parallel and spliced (fmm.cpp, TargetBuild): only cell numbers may differ
  // from the serial build, so every evaluation must agree bit for bit. Both
  // target-tree kinds: a region (the tracer) and known targets (collocation).
  Soup soup = shapes::to_soup(shapes::torus_with(1.0, 0.5, 6400), 1e-3, 5);
  SourceGeometry src = make_sources(soup.positions, soup.triangles, 4);
  std::vector<double> q(src.size());
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> u(0.5, 1.5), box(-2, 2);
  for (double& v : q) v = u(rng);
  std::vector<Vec3> probes;
  for (size_t j = 0; j < src.size(); j += 5) probes.push_back(src.centroid[j]);
  for (int i = 0; i < 500; ++i) probes.push_back({box(rng), box(rng), box(rng) * 0.5});
  Box3 region;
  region.add({-3, -3, -3});
  region.add({3, 3, 3});
  for (bool known_targets : {false, true}) {
    FmmOptions fo;
    fo.order = 6;
    fo.leaf_size = 16;
    fo.threads = 1;
    Fmm serial = known_targets ? Fmm(src, fo, src.centroid) : Fmm(src, fo, region);
    fo.threads = 2;
    Fmm parallel = known_targets ? Fmm(src, fo, src.centroid) : Fmm(src, fo, region);
    EXPECT_EQ(serial.stats().target_cells, parallel.stats().target_cells);
    EXPECT_EQ(serial.stats().m2l_pairs, parallel.stats().m2l_pairs);
    EXPECT_EQ(serial.stats().near_leaf_pairs, parallel.stats().near_leaf_pairs);
    EXPECT_GT(serial.stats().m2l_pairs, 0u);
    serial.set_charges(q);
    parallel.set_charges(q);
    size_t differing = 0, located = 0;
    for (Vec3 x : probes) {
      const int ls = serial.locate(x), lp = parallel.locate(x);
      if (ls < 0 || lp < 0) {
        EXPECT_EQ(ls < 0, lp < 0);
        continue;
      }
      ++located;
      double a = 0, b = 0;
      Vec3 ea{0, 0, 0}, eb{0, 0, 0};
      serial.evaluate(x, &a, &ea);
      parallel.evaluate(x, &b, &eb);
      if (a != b || ea.x != eb.x || ea.y != eb.y || ea.z != eb.z ||
          serial.near_source_triangles(ls) != parallel.near_source_triangles(lp))
        ++differing;
    }
    EXPECT_GT(located, probes.size() / 2) << "known targets " << known_targets;
    EXPECT_EQ(differing, 0u) << "known targets " << known_targets;
  }
}
