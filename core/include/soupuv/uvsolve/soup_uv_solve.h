// The soup UV solve: the one stage after transfer that turns the field
// lines' landing into the final map (ours, not the paper's).
//
// Input : the soup; a weld of its corners; the transferred corner UVs and
//         each corner's landing chart; the atlas's scale (UV units per 3D
//         length) and the continuity texel (UV units); options.
// Output: per soup triangle its corner UVs in [0,1]^2 with, by
//         construction, no flipped triangle, no two islands sharing a
//         texel, and one texel density for the whole map; the figures of
//         each step (diagnostics()).
// Steps : 1. UV mesh (uvsolve/uv_mesh.h): the welded corners that landed
//            together share a vertex; the rest is cut (the transfer's
//            discontinuities).
//         2. Untangle (untangle.h): islands turned positive; an island with
//            folds relaxed as rigidly as possible, kept if it folds less.
//            Islands still folded are flattened again from their own shape
//            (reembed.h: LSCM then SLIM, halved where that fails). Fold cut
//            (fold_cut.h): what still flips or collapses is cut out and
//            unfolded back on by its shape.
//         3. Solve (island_solve.h): SLIM on the symmetric Dirichlet energy,
//            every island at once, cuts fixed.
//         4. Overlap: an island whose image laps over itself, or where
//            different surfaces landed on one place, is flattened again from
//            its own shape (reembed.h); the overlap split (overlap_split.h)
//            cuts what still laps into pieces that do not.
//         5. Joins: the seam between two islands moves to its shortest
//            course nearby where both islands flatten again
//            (seam_straighten.h); islands whose union flattens from its own
//            shape without flips, laps or stretch beyond the budget become
//            one (union_merge.h, longest shared seams first; two halves of
//            a closed part with half their seam left open); then rigid joins
//            across the remaining seams (seam_merge.h), solved and split
//            again.
//         6. Attach (attach_islands.h): islands smaller than their own
//            padding are moved rigidly onto a neighbouring island across a
//            welded edge where that folds and stretches nothing and laps
//            less than a quarter texel. Triangles welded to another island
//            on two or three edges join it where their image there is
//            sound (seam_smooth.h: the seam's teeth).
//         7. Pack (pack_islands.h): the bitmap packer at one density. A
//            map of a few large islands that packs poorly has its largest
//            islands halved along straight UV lines (halve_island.h) and is
//            packed again, where that gains and keeps the continuity target;
//            one still below the utilisation target is packed again the
//            thorough way (pilot rule), kept where denser.
// Cost  : O(n log n) besides the solve's sparse factorisations.
#pragma once

#include <array>
#include <vector>

#include <nlohmann/json.hpp>

#include "soupuv/progress.h"
#include "soupuv/geometry/weld.h"
#include "soupuv/soup.h"

namespace soupuv::uvsolve {

// Maps of at most max_islands islands packed below `below` utilisation: up
// to `rounds` times, the islands of at least half the largest one's area
// are halved where the cut crosses the fewest edges (halve_island.h) and
// the map packed again (while the map is still below
// SoupUvOptions::utilisation_target, up to rounds_below_target times: a
// branching island such as a character's limbs and torso in one piece
// needs a cut per branch); a round is kept while it raises the utilisation
// and leaves at least min_kept_pairs of the welded pairs uncut (the
// product's continuity target: halving never trades it away). A map that
// keeps fewer pairs than that before halving and packs below
// SoupUvOptions::utilisation_target may cut at most max_cut_below_target
// of them more, counted in whole pairs rounded up (its continuity misses
// the target either way; its utilisation need not). The bar and the island count are the atlas's for
// its charts (atlas/build_atlas.h).
struct HalvingOptions {
  uint32_t max_islands = 64;
  double below = 0.72;
  int rounds = 2;
  int rounds_below_target = 8;
  double min_kept_pairs = 0.95;
  double max_cut_below_target = 0.015;
};

struct SoupUvOptions {
  int texture_size = 1024;     // packing raster, texels per side
  double padding_px = 2;       // texels between islands
  // A triangle whose transferred UV area is below this share of its rest
  // area is cut out and unfolded (an almost collapsed image is a fold).
  double collapse_ratio = 0.05;
  int untangle_iterations = 8; // ARAP iterations on islands with a fold
  int solve_iterations = 10;   // SLIM iterations per island at most
  // Seam joins tried per island at most (the longest seams first).
  size_t merge_attempts_per_island = 4;
  // A join that folds is relaxed (ARAP) when the joined island has at most
  // this many triangles (each relaxation is a sparse solve of its size).
  // Over the corpus and the shared samples no relaxation of a larger join
  // was kept (0 of ~190: it unfolds, then laps or folds elsewhere), while
  // they were most of the seam merge's time (docs/tuning.md, session 39).
  size_t merge_relax_max_triangles = 1024;
  // Overlap samples per texel side (2: half-texel spacing).
  double overlap_samples_per_texel = 2;
  // Islands the transfer folded or lapped are flattened again from their
  // own shape (reembed.h) and islands are joined by flattening their union
  // (union_merge.h); a piece or union above this L2 stretch is split or
  // refused. Off: the step list without them (for comparison).
  bool reembed = true;
  double reembed_max_stretch = 1.25;
  // Two islands whose seam is one loop (two halves of a closed part), or
  // whose union is closed, are tried again with half that seam left open
  // where their union has no flat map within the budget (union_merge.h).
  // Off: such unions are refused.
  bool slit_unions = true;
  // Seams between two islands moved to the shortest course in a band
  // around them where both islands flatten again within the stretch budget
  // (seam_straighten.h; needs reembed). Off: seams stay where the transfer
  // and the splits left them.
  bool straighten_seams = true;
  // Islands whose padding would take more texels than they do are attached
  // rigidly to a neighbouring island where that folds and stretches
  // nothing and laps it by at most attach_max_lap_texels (attach_islands.h;
  // in texels of the full square, the finest the packing can reach: a
  // quarter texel is below what a bake at the texture's size resolves).
  // Off: each keeps its own padding.
  bool attach_small_islands = true;
  double attach_max_lap_texels = 0.25;
  // Triangles welded on two or three edges to another island join it where
  // that folds and stretches nothing and laps within the same budget
  // (seam_smooth.h). Off: every triangle stays where the steps above put it.
  bool smooth_seams = true;
  // Stacks of slivers thinner than the noise, each laid out as one grid of
  // rows ranked by height (sliver_stack.h). Off: they keep the islands the
  // steps above gave them.
  bool sliver_stacks = true;
  // Halving a few large islands for packing (HalvingOptions above).
  HalvingOptions halving;
  // The product's utilisation target: a map still packed below it after
  // halving is packed again the thorough way (pack_islands.h), kept where
  // denser; halving.max_cut_below_target applies below it too.
  double utilisation_target = 0.55;
  int threads = 1;
};

struct SoupUvResult {
  std::vector<std::array<Vec2, 3>> corner_uvs;
  nlohmann::json diagnostics;  // the figures of every step, and seconds
};

SoupUvResult solve_soup_uvs(const Soup& soup, const geometry::Weld& weld,
                            const std::vector<std::array<Vec2, 3>>& transferred,
                            const std::vector<int>& corner_chart, double uv_per_length,
                            double texel, const SoupUvOptions& options, Progress& progress);

}  // namespace soupuv::uvsolve
