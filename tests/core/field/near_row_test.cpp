// The near matrix's plain-rule row (near_row.h) against its definition,
// evaluated here in long double: every value within float rounding, every
// near flag as SourceGeometry::is_near decides it, at column counts that
// leave every remainder of the four-column passes.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "field/near_row.h"

using namespace soupuv;
using namespace soupuv::field::detail;

namespace {
NearColumns random_columns(size_t count, int m, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1, 1), radius(0.001, 0.2);
  NearColumns c;
  c.count = count;
  for (size_t k = 0; k < count; ++k) {
    c.cx.push_back(u(rng)), c.cy.push_back(u(rng)), c.cz.push_back(u(rng));
    const double r = 4.0 * radius(rng);
    c.near_r2.push_back(r * r);
  }
  c.px.resize(count * m), c.py.resize(count * m), c.pz.resize(count * m);
  for (int q = 0; q < m; ++q)
    for (size_t k = 0; k < count; ++k) {
      const size_t i = q * count + k;
      c.px[i] = c.cx[k] + 0.05 * u(rng), c.py[i] = c.cy[k] + 0.05 * u(rng), c.pz[i] = c.cz[k] + 0.05 * u(rng);
    }
  return c;
}
}  // namespace

TEST(NearRow, PlainRuleAndNearFlagsMatchTheirDefinition) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  const int m = 6;
  const double w[m] = {0.1, 0.2, 0.15, 0.25, 0.2, 0.1};
  size_t near_seen = 0;
  for (size_t count : {1u, 3u, 4u, 7u, 64u, 2925u}) {
    const NearColumns c = random_columns(count, m, rng);
    for (int row = 0; row < 5; ++row) {
      // Half the rows sit on a column's centroid, so some flags are set.
      const Vec3 x = row % 2 ? Vec3{c.cx[row % count], c.cy[row % count], c.cz[row % count]}
                             : Vec3{u(rng), u(rng), u(rng)};
      std::vector<float> val(count);
      std::vector<uint8_t> near(count, 7);
      plain_near_row(c, m, w, x, val.data(), near.data());
      for (size_t k = 0; k < count; ++k) {
        long double v = 0;
        for (int q = 0; q < m; ++q) {
          const size_t i = q * count + k;
          const long double dx = x.x - c.px[i], dy = x.y - c.py[i], dz = x.z - c.pz[i];
          v += w[q] / std::sqrt(dx * dx + dy * dy + dz * dz);
        }
        ASSERT_NEAR(val[k], double(v), 1.2e-7 * double(v)) << "count " << count << " column " << k;
        const double ex = x.x - c.cx[k], ey = x.y - c.cy[k], ez = x.z - c.cz[k];
        ASSERT_EQ(near[k], (ex * ex + ey * ey) + ez * ez < c.near_r2[k] ? 1 : 0);
        near_seen += near[k];
      }
    }
  }
  EXPECT_GT(near_seen, 0u);
}

TEST(NearRow, APointOnAQuadraturePointGivesAnInfiniteEntryAsTheExactFormDoes) {
  std::mt19937 rng(5);
  const int m = 1;
  const double w[m] = {1.0};
  NearColumns c = random_columns(8, m, rng);
  const Vec3 x{c.px[5], c.py[5], c.pz[5]};
  std::vector<float> val(8);
  std::vector<uint8_t> near(8);
  plain_near_row(c, m, w, x, val.data(), near.data());
  EXPECT_TRUE(std::isinf(val[5]));
  for (size_t k = 0; k < 8; ++k) {
    if (k != 5) {
      EXPECT_TRUE(std::isfinite(val[k]));
    }
  }
}
