// Untangles folded islands before the fold cut (private to the UV solve).
//
// Input : the soup, the rest scale (UV units per 3D length), a layout whose
//         islands are positively oriented as a whole (orient_islands), the
//         collapse ratio (fold_cut.h) and an iteration count.
// Output: every island holding a flipped or collapsed triangle is relaxed by
//         as-rigid-as-possible iterations (Liu et al. 2008: per triangle the
//         rotation closest to its Jacobian, then one sparse solve that fits
//         every triangle to its rotated rest shape). Unlike SLIM's barrier,
//         this energy is finite on flipped triangles, so the fold opens from
//         the island's good surroundings; the island keeps the result only if
//         it has fewer bad triangles than before. What stays folded is then
//         cut by fold_cut.
// Cost  : per island one sparse factorisation, then two solves per
//         iteration.
#pragma once

#include <cstddef>

#include "uvsolve/uv_layout.h"

namespace soupuv::uvsolve::detail {

struct UntangleFigures {
  size_t folded_islands = 0;     // islands with a bad triangle
  size_t untangled_islands = 0;  // of those, kept with fewer bad triangles
  size_t bad_before = 0, bad_after = 0;
};

// Mirrors every island whose area-weighted orientation is negative; returns
// how many.
size_t orient_islands(const Soup& soup, UvLayout& layout);

// Flipped or collapsed: UV area at most collapse_ratio x rest area (a
// degenerate 3D triangle only when flipped).
bool is_folded(const Soup& soup, double uv_per_length, double collapse_ratio, const UvLayout& layout,
               size_t t);
// The same test on a triangle's signed UV area and its rest area (UV units).
bool is_folded(double uv_area, double rest_area, double collapse_ratio);

// The same ARAP iterations on one island (its triangles), in place; false
// if the solve failed (the layout is then unchanged).
bool arap_island(const Soup& soup, double uv_per_length, const std::vector<uint32_t>& tris, int iterations,
                 UvLayout& layout);

UntangleFigures untangle_islands(const Soup& soup, double uv_per_length, double collapse_ratio,
                                 int iterations, int threads, UvLayout& layout);

}  // namespace soupuv::uvsolve::detail
