// The tracer's batched M2L (four sources per SIMD pass) against
// TaylorBasis::m2l, its slow twin, one source at a time: random moments and
// well-separated offsets, lists of every length mod 4 (partial last groups).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "field/tracer_m2l.h"
#include "soupuv/field/taylor.h"

using namespace soupuv;
using namespace soupuv::field;

namespace {

// `count` source cells as BatchM2L takes them: random moments shrinking like
// 0.3^|a| (as a cell of radius ~0.3's do), optionally a positive total charge
// (as the tracer's sources have), and well-separated random offsets.
struct SourceList {
  std::vector<std::vector<double>> M;
  std::vector<const double*> ptr;
  std::vector<Vec3> R;
};

SourceList random_sources(const TaylorBasis& basis, int count, std::mt19937& rng, bool positive_charge) {
  std::uniform_real_distribution<double> u(-1, 1);
  const int n = basis.size();
  SourceList s{std::vector<std::vector<double>>(count, std::vector<double>(n)), std::vector<const double*>(count),
               std::vector<Vec3>(count)};
  for (int i = 0; i < count; ++i) {
    for (int a = 0; a < n; ++a) {
      const auto& A = basis.multi_index(a);
      s.M[i][a] = u(rng) * std::pow(0.3, A[0] + A[1] + A[2]);
    }
    if (positive_charge) s.M[i][0] = 1 + 0.5 * u(rng);
    s.ptr[i] = s.M[i].data();
    Vec3 d{u(rng), u(rng), u(rng)};
    s.R[i] = (1.5 + 2 * std::fabs(u(rng))) * normalized(d);
  }
  return s;
}

}  // namespace

TEST(TracerM2L, MatchesTaylorBasisOnePairAtATime) {
  std::mt19937 rng(5);
  for (int p : {2, 5, 7, 10}) {
    const TaylorBasis basis(p);
    const tracer::BatchM2L batch(basis);
    const int n = basis.size();
    ASSERT_EQ(batch.size(), n);
    for (int count : {1, 2, 3, 4, 5, 7, 8, 13}) {
      const auto [M, ptr, R] = random_sources(basis, count, rng, false);
      std::vector<double> ref(n, 0.0), got(n, 0.25);
      for (int i = 0; i < count; ++i) basis.m2l(M[i].data(), R[i], ref.data());
      batch.apply(ptr.data(), R.data(), count, got.data());
      double scale = 0, worst = 0;
      for (int b = 0; b < n; ++b) scale = std::max(scale, std::fabs(ref[b]));
      // got started at 0.25: apply adds to L.
      for (int b = 0; b < n; ++b) worst = std::max(worst, std::fabs(got[b] - 0.25 - ref[b]));
      EXPECT_LT(worst, 1e-12 * scale) << "p " << p << " count " << count;
    }
  }
}

// The single-precision batch (eight sources per pass) against the double
// one, where it matters: the field of the resulting local expansion at
// points of the target cell (|d| <= 0.3), relative to its size. Lists of
// every length mod 8 (partial last groups).
TEST(TracerM2L, FloatBatchGivesTheSameFieldToFloatRounding) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  double overall = 0;
  for (int p : {2, 5, 7, 10}) {
    const TaylorBasis basis(p);
    const tracer::BatchM2L batch(basis);
    const int n = basis.size();
    for (int count : {1, 3, 7, 8, 9, 13, 16, 23}) {
      const auto [M, ptr, R] = random_sources(basis, count, rng, true);
      std::vector<double> ref(n, 0.0), got(n, 0.0);
      batch.apply(ptr.data(), R.data(), count, ref.data());
      batch.apply_float(ptr.data(), R.data(), count, got.data());
      double worst = 0;
      for (int k = 0; k < 20; ++k) {
        const Vec3 d = 0.3 * Vec3{u(rng), u(rng), u(rng)} / std::sqrt(3.0);
        Vec3 Er{0, 0, 0}, Eg{0, 0, 0};
        basis.l2p(ref.data(), d, nullptr, &Er);
        basis.l2p(got.data(), d, nullptr, &Eg);
        worst = std::max(worst, norm(Eg - Er) / norm(Er));
      }
      EXPECT_LT(worst, 1e-5) << "p " << p << " count " << count;
      overall = std::max(overall, worst);
    }
  }
  std::printf("float M2L: worst field rel. difference %.2e\n", overall);
}
