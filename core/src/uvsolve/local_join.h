// A small island joined onto a larger island's map, which stays as it is
// (private to the UV solve; union_merge.h uses it).
//
// Input : the union as a piece mesh (piece_flatten.h: the larger island's
//         triangles first, `larger` of them, then the smaller's, their seam
//         joined), its triangles, the layout (the larger island's current
//         UVs), the overlap sample spacing, the stretch budget and SLIM's
//         iteration count.
// Output: the union's piece and `kept` when the smaller island fits: the
//         larger island's vertices keep their UVs, the smaller's others
//         come from a conformal map (LSCM's energy, Lévy et al. 2002)
//         pinned to the vertices the two share, then SLIM relaxes them
//         with those pinned; kept on flatten()'s tests (no flip, the
//         union's L2 stretch within the budget, laps within kLapShare).
//         Otherwise the reason: `parts` when fewer than two vertices are
//         shared (the pinned map would be free to turn) or the layout gives
//         a vertex two UVs, `flip`, `stretch` or `overlap`.
// Why   : a join of a few triangles to an island of thousands flattened
//         the whole union again, one serial LSCM and SLIM of thousands of
//         triangles (bracket-exact: 6,565 + 2 triangles, 0.53 s).
// Cost  : the smaller island's LSCM and SLIM, then the union's stretch and
//         lap test.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "uvsolve/piece_flatten.h"
#include "uvsolve/uv_layout.h"

namespace soupuv::uvsolve::detail {

Outcome join_locally(const PieceMesh& mesh, const std::vector<uint32_t>& tris, size_t larger, const UvLayout& layout,
                     double cell, double max_stretch, int solve_iterations, Piece& out);

}  // namespace soupuv::uvsolve::detail
