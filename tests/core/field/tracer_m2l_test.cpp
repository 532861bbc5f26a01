// The tracer's batched M2L (four sources per SIMD pass) against
// TaylorBasis::m2l, its slow twin, one source at a time: random moments and
// well-separated offsets, lists of every length mod 4 (partial last groups).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "../../../core/src/field/tracer_m2l.h"
#include "soupuv/field/taylor.h"

using namespace soupuv;
using namespace soupuv::field;

TEST(TracerM2L, MatchesTaylorBasisOnePairAtATime) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int p : {2, 5, 7, 10}) {
    const TaylorBasis basis(p);
    const tracer::BatchM2L batch(basis);
    const int n = basis.size();
    ASSERT_EQ(batch.size(), n);
    for (int count : {1, 2, 3, 4, 5, 7, 8, 13}) {
      std::vector<std::vector<double>> M(count, std::vector<double>(n));
      std::vector<const double*> ptr(count);
      std::vector<Vec3> R(count);
      for (int i = 0; i < count; ++i) {
        // Moments of a cell of radius ~0.3 shrink like 0.3^|a|, as real ones do.
        for (int a = 0; a < n; ++a) {
          const auto& A = basis.multi_index(a);
          M[i][a] = u(rng) * std::pow(0.3, A[0] + A[1] + A[2]);
        }
        ptr[i] = M[i].data();
        Vec3 d{u(rng), u(rng), u(rng)};
        R[i] = (1.5 + 2 * std::fabs(u(rng))) * normalized(d);
      }
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
