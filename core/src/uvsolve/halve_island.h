// Halving an island for packing (private to the UV solve): a few large
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
//         rectangle at its area median (triangles by centroid); a
//         triangle with two or three edge neighbours across the cut joins
//         them (the seam gets shorter, a few passes); a piece of one side that touches the other only through it goes to the other
//         side, so each half is one piece.
#pragma once

#include <cstdint>

#include "uvsolve/uv_layout.h"

namespace soupuv::uvsolve::detail {

bool halve_island(UvLayout& layout, uint32_t island);

}  // namespace soupuv::uvsolve::detail
