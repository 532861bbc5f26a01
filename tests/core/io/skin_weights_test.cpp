// normalize_skin_weights: weights that already sum to 1 (as the Khronos
// validator adds them, in float32 within 2e-7 per non-zero weight) are left
// bit for bit; others are scaled to pass that same test; weights that cannot
// be normalized (negative, non-finite, all zero) are left for what they are.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "io/skin_weights.h"

namespace soupuv::io::detail {
namespace {

using Sets = std::vector<std::array<float, 4>>;

bool passes_validator(const Sets& sets) { return weights_pass_validator(sets); }

TEST(SkinWeights, NormalizedWeightsAreLeftBitForBit) {
  Sets sets = {{0.1f, 0.2f, 0.3f, 0.4f}};
  ASSERT_TRUE(passes_validator(sets));
  const Sets before = sets;
  EXPECT_FALSE(normalize_skin_weights(sets));
  EXPECT_EQ(sets, before);
  Sets two = {{0.5f, 0, 0, 0}, {0.25f, 0.25f, 0, 0}};
  EXPECT_FALSE(normalize_skin_weights(two));
}

TEST(SkinWeights, OthersAreScaledToPassTheValidator) {
  // Sums like CesiumMan's (0.18 .. 0.99) and one over 1, across one or two sets.
  for (Sets sets : {Sets{{0.1f, 0.05f, 0.03f, 0.007f}}, Sets{{0.7f, 0.2f, 0.08f, 0.009f}},
                    Sets{{0.6f, 0.6f, 0, 0}}, Sets{{0.3f, 0, 0, 0}, {0.1f, 0.1f, 0.2f, 0.05f}},
                    Sets{{1e-3f, 3e-3f, 0.3333f, 0.1f}}}) {
    const Sets before = sets;
    EXPECT_TRUE(normalize_skin_weights(sets));
    EXPECT_TRUE(passes_validator(sets));
    double sum = 0;
    for (const auto& w : before)
      for (float x : w) sum += x;
    for (size_t n = 0; n < sets.size(); ++n)
      for (int c = 0; c < 4; ++c) EXPECT_NEAR(sets[n][c], before[n][c] / sum, 2e-7);
  }
}

TEST(SkinWeights, WeightsThatCannotBeNormalizedAreLeft) {
  for (Sets sets : {Sets{{0, 0, 0, 0}}, Sets{{-0.5f, 0.2f, 0, 0}}, Sets{{NAN, 0.2f, 0, 0}}}) {
    const Sets before = sets;
    EXPECT_FALSE(normalize_skin_weights(sets));
    for (size_t c = 0; c < 4; ++c)
      EXPECT_TRUE(sets[0][c] == before[0][c] || (std::isnan(sets[0][c]) && std::isnan(before[0][c])));
  }
}

}  // namespace
}  // namespace soupuv::io::detail
