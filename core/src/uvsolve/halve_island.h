// Halving islands for packing (private to the UV solve): a few large
// islands fill a square badly (two round blobs leave its corners empty),
// their halves fill the gaps. The halves keep the island's UVs, so they stay
// injective and need no new flattening; the cut costs the welded pairs that
// cross it.
//
// Input : the layout and an island of it.
// Output: the island's triangles on one side of a straight UV line keep its
//         id, the rest become island layout.island_count (incremented), the
//         vertices on the cut duplicated; false (layout unchanged) when the
//         island has fewer than two triangles or the cut does not leave two
//         edge-connected halves.
// Method: the line crosses the long side of the island's minimal-area
//         rectangle where it cuts the fewest edges, each side keeping at
//         least a third of the area (triangles by centroid; ties: nearest
//         the area median); a
//         triangle with two or three edge neighbours across the cut joins
//         them (the seam gets shorter, a few passes); a piece of one side
//         that touches the other only through it goes to the other side,
//         so each half is one piece.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "soupuv/geometry/weld.h"
#include "soupuv/uvsolve/soup_uv_solve.h"
#include "uvsolve/pack_islands.h"
#include "uvsolve/uv_layout.h"

namespace soupuv::uvsolve::detail {

bool halve_island(UvLayout& layout, uint32_t island);

// Packing with halving (HalvingOptions, soup_uv_solve.h). A map whose
// packing `packed` (corner_uvs) fills less than options.below of the
// square: up to options.rounds times (up to options.rounds_below_target
// while below utilisation_target), its islands of at least half the
// largest's area are halved and the map packed again (pack_islands.h) --
// where halving them all would cut too many pairs, the one whose halving
// cuts the fewest alone --; a round is kept (layout, corner_uvs and packed
// replaced) while it raises the utilisation and leaves at least
// min_kept_pairs of the weld's pairs uncut (a map below that before
// halving and packed below utilisation_target: all but
// max_cut_below_target of what it kept). -> each round tried.
struct HalvingRound {
  size_t halved = 0;
  double kept_pairs = 0;  // after the cut
  bool packed = false;    // false: nothing to halve, or the cut kept too few pairs
  double utilisation = 0;
  bool kept = false;
};
std::vector<HalvingRound> halve_to_pack(const std::vector<geometry::AdjacentPair>& pairs,
                                        const HalvingOptions& options, double utilisation_target,
                                        int texture_size, double padding_px,
                                        int threads, UvLayout& layout,
                                        std::vector<std::array<Vec2, 3>>& corner_uvs, PackFigures& packed);

}  // namespace soupuv::uvsolve::detail
