// The low-distortion solve (private to the UV solve): every island of the
// layout flattened at once for the symmetric Dirichlet energy by SLIM
// (transfer/slim.h), its cuts fixed, from the transferred UVs.
//
// Input : the soup, the rest scale (UV units per 3D length), a layout whose
//         triangles are all positively oriented (fold_cut.h), the iteration
//         budget and threads (islands in parallel, largest first).
// Output: the layout's vertices moved; every triangle stays positive (SLIM's
//         flip-free step). A one-triangle island is set to its rest shape.
// Cost  : per island, iterations x one sparse factorisation of its size.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "uvsolve/uv_layout.h"

namespace soupuv::uvsolve::detail {

struct SolveFigures {
  size_t solved_islands = 0;   // islands SLIM moved
  size_t unstarted_islands = 0;  // islands whose start was not flip-free (left as they were)
  double energy_before = 0, energy_after = 0;  // sum over islands, per unit rest area
  int max_iterations_used = 0;
  size_t kept_for_laps = 0;  // islands left as they were: the solve made them lap (lap_cell > 0)
};

// `selected` (per island; null: all): only those islands are solved.
// `lap_cell` > 0: an island whose image covers more overlap samples
// (overlap_split.h, this spacing) after the solve than before keeps its
// UVs (the solve lowers distortion; it must not make the laps the split
// would then cut).
SolveFigures solve_islands(const Soup& soup, double uv_per_length, int max_iterations, int threads,
                           UvLayout& layout, const std::vector<uint8_t>* selected = nullptr,
                           double lap_cell = 0);

}  // namespace soupuv::uvsolve::detail
