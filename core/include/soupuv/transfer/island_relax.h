// Island relaxation: a documented post-process after transfer + UV repair +
// re-weld (not part of the paper's method; MapOptions::island_relax, CLI
// --no-island-relax).
//
// Why: where the soup lands squeezed on the proxy (Fox's thin legs land at
// stretch 2-2.6 while their chart flattened at 1.22), the distortion is
// spread over whole regions; the UV repair re-places small patches with
// their neighbours held fixed and cannot relax a whole leg. This re-flattens
// every UV island as a whole, keeping every cut where it is.
//
// Input : the soup; a weld of its corners (corner -> welded vertex, e.g.
//         weld_corners at the metric's tolerance); corner UVs (3 per
//         triangle); options.
// Output: corner UVs where each accepted island was relaxed, and per-island
//         and total figures. A rejected island keeps its UVs bit for bit.
//
// Method:
//   - Island vertices: the corners of one welded vertex (of `weld`, or of
//     options.also_weld; never two corners of one triangle) whose UVs are
//     continuous (within 1 texel + 2 x their 3D distance at the map's scale,
//     the continuity metric's own test; transitively) are one vertex, at
//     their mean UV; corners apart stay apart. Islands are the components of
//     triangles sharing island vertices. So every pair of the weld that was
//     continuous is inside one island and stays continuous exactly, and no
//     new cut is made.
//   - Energy: the symmetric Dirichlet energy of each triangle against its own
//     3D shape at the map's global scale s = sqrt(UV area / 3D area) (the
//     normalisation of the L2 stretch metric). It is infinite on flips, so a
//     line search with a flip-free step bound keeps every triangle's
//     orientation. Triangles that are flipped, collapsed or 3D-degenerate at
//     the start are left out of the energy and their vertices held fixed.
//   - Solver: SLIM (Rabinovich et al. 2017): per iteration, each triangle's
//     reweighted proxy ||W (J - R)||^2 (R: closest rotation, W from the
//     singular values), one sparse SimplicialLDLT solve of all the island's
//     free vertices, then a step bounded before any triangle degenerates
//     (Smith and Schaefer 2015) and backtracking on the true energy.
//   - Then the L2 metric itself (Sander et al., normalised by the map's UV
//     area: squared L2 = S U / A3^2), with the rest of the map held fixed,
//     by gradient descent preconditioned with the rest shapes' Dirichlet
//     matrix (the symmetric Dirichlet optimum is more conformal than the L2
//     optimum, which lets thin parts widen), same step bound, backtracking.
//   - The result is moved back rigidly onto its start (Procrustes), and into
//     [0,1]^2 (shrunk if it no longer fits). The L2 descent runs in rounds
//     of 10, 40, 160, ... iterations, and every round's result (and SLIM's
//     alone) that passes the checks is a fallback: where the most relaxed
//     island overlaps a neighbour, a less widened one often fits.
//   - Accepted only if the island's area-weighted L2 stretch and the map's
//     drop, every UV
//     stays in [0,1]^2, no triangle flips, and the UV overlap (texel centres
//     of a grid covered by more than one triangle, summed excess) does not
//     grow — checked island by island against the map as it stands.
// Cost  : O(island size x iterations) (sparse LDLT on a surface mesh), plus
//         O(grid^2 + covered texels) for the overlap test.
#pragma once

#include <array>
#include <vector>

#include <nlohmann/json.hpp>

#include "soupuv/progress.h"
#include "soupuv/quality/weld.h"
#include "soupuv/soup.h"

namespace soupuv::transfer {

struct IslandRelaxOptions {
  int max_iterations = 40;   // SLIM iterations on the symmetric Dirichlet energy
  int l2_iterations = 500;   // then preconditioned descent on the L2 metric (0: none)
  // Stop when an iteration lowers the island's energy by less than this
  // fraction.
  double min_relative_decrease = 1e-4;
  // The continuity test's texel: 1 / texture_size, and the UV units per 3D
  // length its noise allowance uses (the atlas's; 0: the map's own scale) —
  // the metric's own test (quality/uv_metrics.h).
  int texture_size = 1024;
  double uv_per_length = 0;
  // Resolution of the overlap test's grid over [0,1]^2.
  int overlap_grid = 2048;
  // Islands with fewer triangles are left alone (nothing to gain).
  size_t min_island_triangles = 4;
  int threads = 0;  // 0 = OpenMP default
  // A second weld of the soup whose groups are joined too (the pipeline
  // passes its edge weld: copies farther apart than the corner weld's
  // tolerance that still match by edges); nullptr: `weld` alone.
  const quality::Weld* also_weld = nullptr;
};

struct IslandFigures {
  size_t triangles = 0, vertices = 0, free_vertices = 0;
  double stretch_l2_before = 0, stretch_l2_after = 0;  // at the map's global scale
  double energy_before = 0, energy_after = 0;          // per 3D area; 4 = isometric
  int iterations = 0, l2_iterations = 0;
  // The result kept: 0 the most relaxed admissible one, 1 the next (an
  // earlier round of the L2 descent, or SLIM's alone) ..., -1 none.
  int choice = -1;
  long overlap_change = 0;  // excess texels added (< 0: removed) when accepted
  std::string outcome;      // relaxed, no_gain, flipped, outside, overlap, small, fixed
  double seconds = 0;
};

struct IslandRelaxResult {
  size_t islands = 0, relaxed = 0;
  size_t rejected_no_gain = 0, rejected_flipped = 0, rejected_outside = 0, rejected_overlap = 0;
  size_t skipped_small = 0, skipped_fixed = 0;
  // Corners whose UV differs from their island vertex's mean UV (within the
  // continuity tolerance; joined only where their island is accepted).
  size_t snapped_corners = 0;
  size_t moved_corners = 0;
  double stretch_l2_before = 0, stretch_l2_after = 0;  // whole map, metric's normalisation
  long overlap_texels_before = 0, overlap_texels_after = 0;  // summed excess coverage
  std::vector<IslandFigures> per_island;  // largest first
  double seconds = 0;
  nlohmann::json diagnostics(size_t max_islands = 12) const;
};

IslandRelaxResult relax_islands(const Soup& soup, const quality::Weld& weld,
                                std::vector<std::array<Vec2, 3>>& corner_uvs,
                                const IslandRelaxOptions& options = {},
                                Progress& progress = Progress::none());

}  // namespace soupuv::transfer
