// Intersecting soup triangles (paper §12.1, Fig. 19).
//
// When one soup triangle cuts through another, the cut triangle's corners lie
// on different sides of the cutting surface and their field lines reach
// different parts of the proxy: the triangle's texture tears. We
//   1. find the cutting pairs: BVH over triangle boxes, then an exact-ish
//      triangle-triangle test (the two plane-crossing segments overlapping on
//      the planes' common line). A pair only counts when the cut is deeper than
//      `min_depth` on both sides of the cut triangle, so the tiny crossings
//      that vertex noise creates between neighbours are not refined;
//   2. split every cut triangle by the planes of its cutters (polygon
//      clipping, fan triangulation), so each piece lies on one side — the
//      refined soup is what gets charged;
//   3. the writer outputs the ORIGINAL triangles and only their corners are
//      traced: the refinement changes the charge, not what is mapped.
//
// Input : a soup; min_depth (absolute; 0 = 5e-3 x bounding-box diagonal, above
//         the crossings that the shared soups' 1e-3 vertex noise makes).
// Output: the refined soup, its parent map and counts.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <nlohmann/json.hpp>

#include "soupuv/progress.h"
#include "soupuv/soup.h"

namespace soupuv::field {

struct IntersectionRefinement {
  Soup soup;                        // refined soup (uncut triangles unchanged)
  std::vector<uint32_t> parent;     // original triangle of each refined triangle
  size_t intersecting_pairs = 0;
  size_t cut_triangles = 0;
  nlohmann::json diagnostics() const;
};

IntersectionRefinement refine_intersections(const Soup& soup, Progress& progress,
                                            double min_depth = 0);

}  // namespace soupuv::field
