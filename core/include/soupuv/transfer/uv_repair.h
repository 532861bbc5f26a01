// Local UV repair: a documented post-process after transfer + chart fix
// (not part of the paper's method; switch it off with MapOptions::uv_repair).
//
// The field-line map is good almost everywhere (median stretch ~1.05-1.25),
// but where lines converge at concave creases or miss the proxy a few UV
// triangles collapse to slivers or fold over, and they carry nearly all of
// the L2 stretch and all flips. This re-places only the UVs around them.
//
// Input : the soup; a weld (corner -> welded vertex); the chart of every soup
//         triangle (after §8 all its corners are on one chart); the atlas's
//         global texel scale (UV units per 3D length); corner UVs.
// Output: corner UVs where the welded vertices of bad triangles (flipped,
//         collapsed, or stretched far beyond the median) were moved, and
//         counts. Every other corner keeps its UV bit for bit.
//
// Method: a "UV vertex" is a (welded vertex, chart) pair. The UV vertices of
// bad triangles that touch each other form a patch; its triangles are every
// soup triangle on that chart using one of them, and all their other UV
// vertices stay fixed (each fixed corner keeps its own UV). A patch with no
// fixed corner at all (a chart island) starts from one triangle laid down
// isometrically at its own UV and the rest unfolded from it. Otherwise start
// from a flip-free placement: the free vertices at the mean of their copies, or if
// that folds, a Tutte embedding (uniform weights) inside the fixed ones, or
// an unfolding from the fixed corners inwards; if all fold (a fan open at a
// chart border, a chart island with no fixed corner at all, a concave ring),
// untangle from the copies' mean: descend on Garanzha et al.'s regularised
// energy (untangle_energy.h), finite on folds, lowering its eps until every
// triangle is positive. If nothing works, grow the patch by one ring and try
// again (max_growth times); a repaired patch whose triangles are still bad
// grows too, from its repaired UVs (grow_while_bad).
// Then minimise the symmetric Dirichlet energy of the patch's triangles
// against their own 3D shape at the global scale (isometric = minimum; it is
// infinite for a collapsed or flipped triangle, so a line search that keeps
// every triangle's orientation keeps the map injective on the patch), by
// preconditioned block coordinate descent, one free vertex at a time. A patch
// is written back only if its energy went down and every triangle in it keeps
// at least 1/1000 of its isometric UV area (nothing folded or collapsed).
// Cost  : O(patch size x sweeps) per patch; patches are small and disjoint.
#pragma once

#include <array>
#include <vector>

#include <nlohmann/json.hpp>

#include "soupuv/progress.h"
#include "soupuv/quality/weld.h"
#include "soupuv/soup.h"

namespace soupuv::transfer {

struct UvRepairOptions {
  // A triangle is bad when its UV orientation is against the dominant one,
  // when its UV area collapsed, when its L2 stretch (Sander et al., UV onto
  // surface, at the global scale) exceeds stretch_threshold x the
  // area-weighted median, or when it is enlarged along some direction by
  // more than expansion_threshold (the largest singular value of the
  // surface -> UV map at the global scale).
  double stretch_threshold = 2.0;
  double expansion_threshold = 4.0;
  // Never move a UV vertex whose welded vertex also lies on another chart,
  // so pairs across a seam that matched stay matched. Off: measured, it
  // keeps most bad triangles (they sit at seams) and continuity did not
  // rise (spot L2 3.60 vs 2.03, suzanne continuity 0.8634 vs 0.8620).
  bool keep_seam_vertices = false;
  int max_growth = 3;                // rings added to a patch with no flip-free start
  // A repaired patch whose triangles are still bad grows by a ring too (up
  // to max_growth), from its repaired UVs, while the energy keeps dropping:
  // where lines converged over a whole region, the ring the first repair
  // held fixed is itself squeezed. One binary, loaded machine, L2 without ->
  // with: spot 1.247 -> 1.109, Duck 1.214 -> 1.083 (continuity unchanged),
  // CesiumMan 1.261 -> 1.152, Fox 1.133 -> 1.100 (1.452 -> 1.202 with a
  // 130 deg merge cone), suzanne 1.180 -> 1.111, teapot 0.9551 / 0.158 % /
  // 1.123 -> 0.9541 / 0.127 % / 1.103; 100k torus unchanged (1.152, its
  // one flipped sliver).
  bool grow_while_bad = true;
  // ... but only while the repaired patch has at most this many free UV
  // vertices (0: no bound). A patch of thousands of vertices is a whole
  // region landed badly; each ring re-minimises all of it, and one such
  // patch took 3 of a 100k re-run's 7.6 s (4 rings, 2,578 vertices).
  size_t grow_while_bad_max_vertices = 0;
  // When the copies' mean, Tutte and unfolding all fold, untangle
  // (Garanzha et al. 2021) from the copies' mean for up to untangle_rounds
  // rounds of its eps schedule.
  bool untangle = true;
  // A patch with no fixed corner (a chart island: triangles whose corners
  // landed on two charts, a part cut off by the weld) starts from one
  // triangle laid down isometrically at its corner 0's UV, the rest unfolded
  // from it. Off: such patches start like the others (fandisk: 3-4 of them
  // failed as slivers, flipped 0.05 % / L2 1.36 vs 0 / 1.17 with it).
  bool island_start = true;
  // ... only for islands of at most this many triangles: a larger one is a
  // whole chart (e.g. a plate traced mirrored), which the island start would
  // lay down over other charts (Fig. 19 planes: flipped 0 -> 14 % unlimited).
  size_t island_max_triangles = 32;
  int untangle_rounds = 30;
  int max_sweeps = 100;              // coordinate-descent sweeps per patch
  size_t max_patch_vertices = 4000;  // larger patches are left alone (counted)
  // The chart each corner landed on (3 per triangle), when a triangle's
  // corners may lie on different charts (§8 could not bring them onto one):
  // such corners are repaired onto the triangle's chart (triangle_chart).
  // nullptr: every corner is on its triangle's chart.
  const std::vector<int>* corner_chart = nullptr;
  // Only these triangles may seed patches (e.g. a retry of the failed
  // patches of an earlier pass, UvRepairResult::failed_triangles); nullptr:
  // every bad triangle.
  const std::vector<uint32_t>* only_triangles = nullptr;
};

struct UvRepairResult {
  size_t bad_triangles = 0;        // before the repair
  size_t bad_triangles_after = 0;
  size_t patches = 0;
  size_t repaired_patches = 0;     // written back
  size_t failed_patches = 0;       // no flip-free start, too large, or no gain
  // ... by the reason of the last try (after growing max_growth rings):
  // both starts folded, the energy did not drop, a triangle stayed a
  // sliver, or the patch outgrew max_patch_vertices.
  size_t failed_no_start = 0, failed_no_gain = 0, failed_sliver = 0, failed_too_large = 0;
  size_t repaired_vertices = 0;    // UV vertices (welded vertex, chart) moved
  size_t repaired_triangles = 0;   // soup triangles with a moved corner
  // The first failed patches at their last try: a triangle of the seed,
  // sizes, fixed corners, 3D-degenerate triangles, reason.
  nlohmann::json failed_detail = nlohmann::json::array();
  // The slowest patches (at most 3, slowest first): seconds, seed and final
  // free vertices, triangles, rings tried, repaired or not — where the
  // repair's time goes when one patch dominates it.
  nlohmann::json slowest_patches = nlohmann::json::array();
  // Every triangle around a failed patch's seed vertices (sorted, unique).
  std::vector<uint32_t> failed_triangles;
  double seconds = 0;
  nlohmann::json diagnostics() const;
};

UvRepairResult repair_uvs(const Soup& soup, const quality::Weld& weld,
                          const std::vector<int>& triangle_chart, double uv_per_length,
                          std::vector<std::array<Vec2, 3>>& corner_uvs,
                          const UvRepairOptions& options = {},
                          Progress& progress = Progress::none());

}  // namespace soupuv::transfer
