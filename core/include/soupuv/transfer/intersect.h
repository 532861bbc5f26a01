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
//   3. because the writer outputs the ORIGINAL triangles, the UVs map back
//      like this: only original corners are traced, plus three probe points
//      inside the largest piece of each cut triangle; a corner on another
//      side than that piece gets its UV by the affine map (3D in the
//      triangle's plane -> UV) fitted to the probes (apply_cut_probes), so the
//      whole original triangle wears the texture of one side, undistorted.
//
// Input : a soup; min_depth (absolute; 0 = 5e-3 x bounding-box diagonal, above
//         the crossings that the shared soups' 1e-3 vertex noise makes).
// Output: the refined soup, its parent map, probe points and counts.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <nlohmann/json.hpp>

#include "soupuv/progress.h"
#include "soupuv/soup.h"

namespace soupuv::transfer {

struct CutProbe {
  uint32_t triangle = 0;            // original soup triangle
  std::array<Vec3, 3> points;       // inside its largest piece
  std::array<bool, 3> corner_off{}; // corners NOT on that piece's side (to extrapolate)
};

struct IntersectionRefinement {
  Soup soup;                        // refined soup (uncut triangles unchanged)
  std::vector<uint32_t> parent;     // original triangle of each refined triangle
  std::vector<CutProbe> probes;     // one per cut triangle
  size_t intersecting_pairs = 0;
  size_t cut_triangles = 0;
  nlohmann::json diagnostics() const;
};

IntersectionRefinement refine_intersections(const Soup& soup, Progress& progress,
                                            double min_depth = 0);

// For every probe whose three probe points landed at probe_uvs[3*i .. 3*i+2]:
// the corners of its triangle marked corner_off get the UV of the affine map
// fitted to the probes (3D, in the triangle's plane -> UV). Returns the number
// of triangles changed.
size_t apply_cut_probes(const Soup& soup, const std::vector<CutProbe>& probes,
                        const std::vector<Vec2>& probe_uvs,
                        std::vector<std::array<Vec2, 3>>& corner_uvs);

// Exact-ish triangle-triangle intersection: true when the triangles share a
// segment of positive length (coplanar pairs are reported as not cutting).
bool triangles_intersect(const std::array<Vec3, 3>& a, const std::array<Vec3, 3>& b);

}  // namespace soupuv::transfer
