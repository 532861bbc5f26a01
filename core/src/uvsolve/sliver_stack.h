// Stacks of slivers thinner than the noise, laid out as one grid each
// (private to the UV solve).
//
// Input : the soup, its weld's adjacent pairs (geometry::edge_adjacency),
//         the rest scale (UV units per 3D length) and a layout whose
//         islands are final (before packing).
// Output: every stack found gets its own island, laid out as a grid:
//         columns at the positions along the slivers' long direction where
//         their ends cluster, rows of equal height across the stack; in
//         each column the slivers whose short edge is on the left and those
//         whose short edge is on the right are each ranked by height, the
//         k-th of each filling row k as the two halves of one quad (the
//         diagonal's direction by the stack's majority). Every triangle
//         takes the stack's majority orientation, so none flips; the
//         quads tile the grid, so none laps another. Triangles left out of
//         a stack keep their island.
//         A stack: slivers (altitude below kThinNoise noise amplitudes and
//         below kMaxAspect of their longest edge, which is at least
//         kLongNoise amplitudes long) with parallel long edges, joined by
//         weld pairs or lying within three amplitudes of each other, flat
//         across (within the noise), whose columns hold as many left as
//         right slivers (a few may be missing), at least two columns, with
//         rows thinner than twice the noise amplitude: the soup does not
//         resolve their order (the yardstick counts edges shorter than that
//         as unresolved, but the rows' long edges are resolved).
//         A group of parallel slivers that is not flat (a thin bar's four
//         sides) is split into its flat sides first, each the line across
//         the slivers through the most of their centroids. A stack is laid
//         out only where the grid keeps more of the weld's pairs than the
//         islands it is in: more pairs inside it cut now than pairs to the
//         rest of the part kept now (the grid's island is packed apart).
//         The noise amplitude is estimated from the weld: the RMS distance
//         between welded corner copies over sqrt 2 (uniform noise of
//         amplitude a per coordinate gives sqrt(2) a).
// Why   : CAD exports tessellate a thin side (a table top's edge band, a
//         board's sides) into a column of long slivers. Where the noise
//         exceeds their height the weld cannot tell which long edges meet,
//         the welded strip folds, and the stages before cut it into
//         singletons and pairs packed apart: the table's top lost 60 % of
//         its side bands' resolved edges, the enclosure's hidden board 36 %
//         (docs/tuning.md, "Sliver stacks"). Ranked by height, a sliver
//         lands within a row or two of its place, a sub-texel distance, so
//         its true neighbours stay next to it whatever the weld said.
// Cost  : O(pairs) for the noise and the groups, O(n log n) in the slivers
//         to sort them into columns and rows; a group that is not flat adds
//         180 sorts of at most 4,096 centroids per side searched (table:
//         0.1-0.2 s in all, other corpus soups at most 0.03 s).
#pragma once

#include <cstddef>
#include <vector>

#include "soupuv/geometry/weld.h"
#include "soupuv/soup.h"
#include "uvsolve/uv_layout.h"

namespace soupuv::uvsolve::detail {

struct SliverStackFigures {
  double noise = 0;           // the estimated noise amplitude (3D length)
  size_t stacks = 0;          // stacks laid out as grids
  size_t columns = 0;         // their columns
  size_t triangles = 0;       // their triangles
  size_t skipped_stacks = 0;  // candidate groups refused (rows resolved, not flat, not a grid)
  size_t kept_by_islands = 0; // stacks left where their islands keep more of the weld's pairs
};

SliverStackFigures lay_sliver_stacks(const Soup& soup, const std::vector<geometry::AdjacentPair>& pairs,
                                     double uv_per_length, UvLayout& layout);

}  // namespace soupuv::uvsolve::detail
