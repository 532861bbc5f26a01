// Triangle rules: exact on every monomial up to their degree, not beyond
// (which shows the test can fail), and no point at the centroid.
#include <gtest/gtest.h>

#include <cmath>

#include "soupuv/errors.h"
#include "soupuv/field/quadrature.h"

using namespace soupuv::field;

namespace {
double factorial(int n) { return n <= 1 ? 1.0 : n * factorial(n - 1); }

// Exact mean of x^i y^j over the unit right triangle (0,0),(1,0),(0,1): 2 * i! j! / (i+j+2)!.
double exact_mean(int i, int j) { return 2.0 * factorial(i) * factorial(j) / factorial(i + j + 2); }

double rule_mean(const TriangleRule& r, int i, int j) {
  double s = 0;
  for (size_t k = 0; k < r.weights.size(); ++k) {
    double x = r.points[k][1], y = r.points[k][2];  // vertices (0,0), (1,0), (0,1)
    s += r.weights[k] * std::pow(x, i) * std::pow(y, j);
  }
  return s;
}
}  // namespace

TEST(Quadrature, ExactUpToDegree) {
  for (int degree : {2, 4, 6}) {
    const TriangleRule& r = triangle_rule(degree);
    EXPECT_EQ(r.degree, degree);
    for (int total = 0; total <= degree; ++total)
      for (int i = 0; i <= total; ++i)
        EXPECT_NEAR(rule_mean(r, i, total - i), exact_mean(i, total - i), 1e-13)
            << "degree " << degree << " monomial x^" << i << " y^" << total - i;
    // One degree higher is no longer exact for some monomial.
    double worst = 0;
    for (int i = 0; i <= degree + 1; ++i)
      worst = std::max(worst, std::fabs(rule_mean(r, i, degree + 1 - i) - exact_mean(i, degree + 1 - i)));
    EXPECT_GT(worst, 1e-8) << "degree " << degree;
  }
}

TEST(Quadrature, PointCountsAndNoCentroid) {
  EXPECT_EQ(triangle_rule(2).points.size(), 3u);
  EXPECT_EQ(triangle_rule(4).points.size(), 6u);
  EXPECT_EQ(triangle_rule(6).points.size(), 12u);
  for (int degree : {2, 4, 6})
    for (const auto& p : triangle_rule(degree).points) {
      double d = std::fabs(p[0] - 1.0 / 3) + std::fabs(p[1] - 1.0 / 3) + std::fabs(p[2] - 1.0 / 3);
      EXPECT_GT(d, 1e-3);
      EXPECT_NEAR(p[0] + p[1] + p[2], 1.0, 1e-14);
      EXPECT_GT(p[0], 0.0);
      EXPECT_GT(p[1], 0.0);
      EXPECT_GT(p[2], 0.0);
    }
}

TEST(Quadrature, RejectsOtherDegrees) {
  EXPECT_THROW(triangle_rule(3), soupuv::Error);
}
