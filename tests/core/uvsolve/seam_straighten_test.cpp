// Seams moved to their shortest course (seam_straighten.h): a flat sheet in
// two islands whose seam zigzags one cell to and fro from row to row is
// divided again along a straight line, each island without a flipped
// triangle; a seam that is already straight is left as it is.
#include "uvsolve/seam_straighten.h"

#include <gtest/gtest.h>

#include "two_islands.h"

namespace soupuv {
namespace {

using test::kScale;
using test::TwoIslands;

constexpr int kN = 20;

// Cells right of the middle are island 1; with `zigzag`, every other row's
// boundary one cell further left.
TwoIslands sheet(bool zigzag) {
  return test::two_islands(test::grid_sheet(kN), [zigzag](size_t t) {
    const int i = int(t / 2) / kN, j = int(t / 2) % kN;
    return uint32_t(i >= kN / 2 - (zigzag && j % 2 == 0 ? 1 : 0));
  });
}

uvsolve::detail::SeamStraightenFigures straighten(TwoIslands& h) {
  return uvsolve::detail::straighten_seams(h.soup, kScale, h.pairs, /*cell=*/0.5, /*max_stretch=*/1.25,
                                           /*solve_iterations=*/10, /*threads=*/2, h.layout);
}

TEST(SeamStraighten, AZigzagSeamIsMovedToAStraightLine) {
  TwoIslands h = sheet(true);
  ASSERT_EQ(test::seam_pairs(h.pairs, h.layout), size_t(2 * kN - 1));  // kN across, kN - 1 steps
  const auto f = straighten(h);
  EXPECT_EQ(f.straightened, 1u);
  EXPECT_EQ(f.pairs_gained, size_t(kN - 1));
  EXPECT_EQ(test::seam_pairs(h.pairs, h.layout), size_t(kN));
  EXPECT_EQ(h.layout.island_count, 2u);
  EXPECT_EQ(test::flipped_triangles(h.layout), 0u);
  // Every pair inside an island is joined (its corners share vertices).
  const double kept = uvsolve::detail::kept_pair_share(h.pairs, h.layout);
  EXPECT_DOUBLE_EQ(kept * double(h.pairs.size()), double(h.pairs.size() - kN));
}

TEST(SeamStraighten, AStraightSeamIsLeftAsItIs) {
  TwoIslands h = sheet(false);
  const auto before = h.layout.corner_vertex;
  const auto f = straighten(h);
  EXPECT_EQ(f.seams, 1u);
  EXPECT_EQ(f.shorter, 0u);
  EXPECT_EQ(h.layout.corner_vertex, before);
}

}  // namespace
}  // namespace soupuv
