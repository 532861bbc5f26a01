// Joins islands by flattening their union anew (private to the UV solve).
//
// Input : the soup, the rest scale (UV units per 3D length), the weld's
//         adjacent pairs (geometry::edge_adjacency), the overlap sample
//         spacing (overlap_split.h), the stretch budget and SLIM iterations
//         of piece_flatten.h, attempts per island, and a layout.
// Output: for each two islands sharing welded edges (the longest shared
//         seam first, each island in at most attempts_per_island tries),
//         the union with its seam closed (the shared corners one vertex) is
//         flattened from its own shape (piece_flatten.h); an island at most
//         an eighth of the other's size is first joined onto the larger
//         one's map as it stands (local_join.h). When that is kept
//         (no flip, within the stretch budget, no lap) the two become one
//         island with the new UVs. With `slit`, a union refused as closed,
//         or refused for stretch or a fold while its seam is one loop or its
//         outline is shorter than a hemisphere's of its area, is flattened
//         once more with half its seam's longest chain left open.
// Why   : the rigid join (seam_merge.h) can only close a seam where the two
//         islands' existing maps already fit; most seams the transfer, the
//         folds and the overlaps cut lie between islands whose shapes would
//         flatten together but whose current maps do not.
// Cost  : per attempt one flattening of the union, all of them within a
//         budget of 8 times the soup's triangles (a union above 3,000
//         triangles counted larger, as its flattening costs more per
//         triangle; a local join counts as the smaller island's
//         flattening, and the union's flattening after a failed one is
//         counted when it is made, as is a second one with the seam half
//         open), and no one flattening costing more
//         than 2.5 times the soup's size in those units (a union that
//         would is not tried, nor flattened after a failed local join);
//         attempts on disjoint islands run on `threads` threads. An
//         attempt on two islands refused before, neither changed since,
//         is answered from that refusal (it counts as
//         tried, so the result is the same); so is one whose union holds a
//         union refused for its stretch and is forecast to stay above the
//         budget (union_merge.cpp).
// Progress: `on_round` (when set) is called between rounds, outside the
//         threads, with the share of the seams dealt with so far; it may
//         throw (a canceled job) and nothing is left half-applied.
#pragma once

#include <cstddef>
#include <functional>
#include <vector>

#include "soupuv/geometry/weld.h"
#include "uvsolve/uv_layout.h"

namespace soupuv::uvsolve::detail {

struct UnionMergeFigures {
  size_t attempts = 0;
  size_t joined = 0;
  size_t repeated = 0;  // attempts on two islands refused before as they are: not flattened again
  size_t forecast_refused = 0;  // attempts holding a union refused for stretch, forecast to stay above the budget
  size_t joined_locally = 0;    // joins made onto the larger island's map as it stood (local_join.h)
  size_t slit = 0;              // joins made with half the seam left open (a closed union)
};

UnionMergeFigures merge_by_reflattening(const Soup& soup, double uv_per_length,
                                        const std::vector<geometry::AdjacentPair>& pairs, double cell,
                                        double max_stretch, int solve_iterations, size_t attempts_per_island,
                                        bool slit, int threads, UvLayout& layout,
                                        const std::function<void(double share)>& on_round = {});

}  // namespace soupuv::uvsolve::detail
