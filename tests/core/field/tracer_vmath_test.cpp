// The tracer's AVX2 log and atan2 (core/src/field/tracer_vmath.h) against
// std::log / std::atan2: over the whole normal range, next to 1 (log) and
// next to the reduction's split points (atan2), every sign combination, the
// arguments the closed form produces (ratios of nearly equal distances,
// tiny solid angles, angles past pi/2), and the edge cases left to std.
#include <gtest/gtest.h>

#include <cfloat>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "field/tracer_vmath.h"

#ifdef SOUPUV_TRACER_VMATH

using namespace soupuv::field;

namespace {

__attribute__((target("avx2,fma"))) std::vector<double> vlog_all(const std::vector<double>& a) {
  std::vector<double> out(a.size());
  for (size_t i = 0; i + 4 <= a.size(); i += 4) _mm256_storeu_pd(&out[i], tracer::vlog(_mm256_loadu_pd(&a[i])));
  return out;
}

__attribute__((target("avx2,fma"))) std::vector<double> vlog_ratio_all(const std::vector<double>& n,
                                                                        const std::vector<double>& d) {
  std::vector<double> out(n.size());
  for (size_t i = 0; i + 4 <= n.size(); i += 4)
    _mm256_storeu_pd(&out[i], tracer::vlog_ratio(_mm256_loadu_pd(&n[i]), _mm256_loadu_pd(&d[i])));
  return out;
}

__attribute__((target("avx2,fma"))) std::vector<double> vatan2_all(const std::vector<double>& y,
                                                                    const std::vector<double>& x) {
  std::vector<double> out(y.size());
  for (size_t i = 0; i + 4 <= y.size(); i += 4)
    _mm256_storeu_pd(&out[i], tracer::vatan2(_mm256_loadu_pd(&y[i]), _mm256_loadu_pd(&x[i])));
  return out;
}

// Error in units of the result's magnitude (relative), with |ref| floored
// at DBL_MIN so log(1) = 0 must come out exact.
double rel(double got, double ref) {
  if (got == ref) return 0;
  return std::fabs(got - ref) / std::max(std::fabs(ref), DBL_MIN);
}

}  // namespace

TEST(TracerVmath, LogMatchesStd) {
  if (!tracer::vmath_supported()) GTEST_SKIP() << "no AVX2+FMA";
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(0, 1), expo(-300, 300), near(-16, -1);
  std::vector<double> a;
  for (int i = 0; i < 200000; ++i) a.push_back(std::pow(10.0, expo(rng)) * (1 + u(rng)));  // whole range
  for (int i = 0; i < 200000; ++i) {                                                     // next to 1
    const double d = std::pow(10.0, near(rng));
    a.push_back(i % 2 ? 1 + d : 1 - d);
  }
  for (int i = 0; i < 100000; ++i) a.push_back(M_SQRT2 * (1 + (u(rng) - 0.5) * 1e-6));  // the m split
  // The closed form's edge-log arguments: (R_j + s+) / (R_i + s-) with
  // nearly equal terms, and over the floored distance (up to ~1e30).
  for (int i = 0; i < 100000; ++i) a.push_back((1 + u(rng)) / std::pow(10.0, 30 * u(rng) - 1));
  a.insert(a.end(), {1.0, 2.0, 0.5, DBL_MIN, DBL_MAX, 4.0, 0.25, 1e-300, 1e300});
  while (a.size() % 4) a.push_back(1.0);
  const std::vector<double> got = vlog_all(a);
  double worst = 0, worst_far = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    const double e = rel(got[i], std::log(a[i]));
    if (std::fabs(a[i] - 1) < 0.5) worst = std::max(worst, e);
    else worst_far = std::max(worst_far, e);
  }
  std::printf("vlog vs std::log, max rel difference: next to 1 %.2e, elsewhere %.2e\n", worst, worst_far);
  EXPECT_LT(worst, 1e-15);
  EXPECT_LT(worst_far, 1e-15);
  EXPECT_EQ(vlog_all({1.0, 1.0, 1.0, 1.0})[0], 0.0);  // log(1) exact
}

TEST(TracerVmath, LogEdgeCasesAreStd) {
  if (!tracer::vmath_supported()) GTEST_SKIP() << "no AVX2+FMA";
  const double inf = std::numeric_limits<double>::infinity();
  const std::vector<double> a = {0.0, inf, 4.9e-324, 1e-310, DBL_MIN / 2, 2.0, 0.5, -1.0};
  const std::vector<double> got = vlog_all(a);
  for (size_t i = 0; i < a.size(); ++i) {
    const double ref = std::log(a[i]);
    if (std::isnan(ref)) EXPECT_TRUE(std::isnan(got[i])) << a[i];
    else EXPECT_EQ(got[i], ref) << a[i];
  }
}

// log(n / d) against the long double log of the long double quotient:
// next to n = d std::log(n / d) itself loses digits (n / d is rounded first),
// vlog_ratio does not.
TEST(TracerVmath, LogRatioMatchesLongDouble) {
  if (!tracer::vmath_supported()) GTEST_SKIP() << "no AVX2+FMA";
  std::mt19937_64 rng(13);
  std::uniform_real_distribution<double> u(0, 1), expo(-150, 150), near(-15, -1);
  std::vector<double> n, d;
  for (int i = 0; i < 200000; ++i) {
    n.push_back(std::pow(10.0, expo(rng)) * (1 + u(rng)));
    d.push_back(std::pow(10.0, expo(rng)) * (1 + u(rng)));
  }
  for (int i = 0; i < 200000; ++i) {  // ratios next to 1, and next to the sqrt(2) splits
    const double x = std::pow(10.0, 20 * u(rng) - 10) * (1 + u(rng));
    const double r = (i % 3 == 0 ? 1 : i % 3 == 1 ? M_SQRT2 : M_SQRT1_2) * (1 + (i % 2 ? 1 : -1) * std::pow(10.0, near(rng)));
    n.push_back(x * r);
    d.push_back(x);
  }
  const std::vector<double> got = vlog_ratio_all(n, d);
  double worst = 0;
  for (size_t i = 0; i < n.size(); ++i) {
    // Next to n = d: n - d is exact, so log1p of the long double (n - d) / d.
    const long double ln = n[i], ld = d[i];
    const long double ref = (n[i] > 0.5 * d[i] && n[i] < 2 * d[i]) ? std::log1p((ln - ld) / ld) : std::log(ln / ld);
    if (ref == 0) {
      EXPECT_EQ(got[i], 0.0);
      continue;
    }
    worst = std::max(worst, static_cast<double>(std::fabs((got[i] - ref) / ref)));
  }
  std::printf("vlog_ratio vs long double log(n / d), max rel difference %.2e\n", worst);
  EXPECT_LT(worst, 1e-15);
  const double inf = std::numeric_limits<double>::infinity();
  const std::vector<double> en = {1.0, 0.0, 2.0, 1e-310}, ed = {0.0, 1.0, 1e-320, 1.0};
  const std::vector<double> eg = vlog_ratio_all(en, ed);
  for (size_t i = 0; i < en.size(); ++i) EXPECT_EQ(eg[i], std::log(en[i] / ed[i])) << en[i] << " / " << ed[i];
  EXPECT_EQ(eg[0], inf);
}

TEST(TracerVmath, Atan2MatchesStd) {
  if (!tracer::vmath_supported()) GTEST_SKIP() << "no AVX2+FMA";
  std::mt19937_64 rng(12);
  std::uniform_real_distribution<double> u(-1, 1), expo(-12, 3);
  std::vector<double> y, x;
  auto push = [&](double yy, double xx) {
    y.push_back(yy);
    x.push_back(xx);
  };
  for (int i = 0; i < 200000; ++i) push(u(rng) * std::pow(10.0, expo(rng)), u(rng) * std::pow(10.0, expo(rng)));
  // Ratios next to the reduction's split points tan((2j+1) pi/32) and c_j.
  for (int i = 0; i < 100000; ++i) {
    const double angle = (i % 16) * M_PI / 32 + u(rng) * 1e-7;
    push(std::sin(angle) * (i % 3 ? 1 : -1), std::cos(angle) * (i % 5 ? 1 : -1));
  }
  // The solid angle: y = |det| >= 0 tiny next to x, and x < 0 (angles past pi/2).
  for (int i = 0; i < 100000; ++i) push(std::fabs(u(rng)) * std::pow(10.0, -16 * std::fabs(u(rng))), u(rng));
  for (double yy : {0.0, -0.0, 1.0, -1.0})
    for (double xx : {0.0, -0.0, 1.0, -1.0, 1e-300, -1e-300}) push(yy, xx);
  while (y.size() % 4) push(1, 1);
  const std::vector<double> got = vatan2_all(y, x);
  double worst = 0;
  for (size_t i = 0; i < y.size(); ++i) {
    const double ref = std::atan2(y[i], x[i]);
    worst = std::max(worst, rel(got[i], ref));
    if (ref == 0) {
      EXPECT_EQ(got[i], 0.0) << y[i] << " " << x[i];
    }
    ASSERT_EQ(std::signbit(got[i]), std::signbit(ref)) << y[i] << " " << x[i];
  }
  std::printf("vatan2 vs std::atan2, max rel difference %.2e\n", worst);
  EXPECT_LT(worst, 1e-15);
}

#else
TEST(TracerVmath, NotX86) { GTEST_SKIP() << "AVX2 code not built on this target"; }
#endif
