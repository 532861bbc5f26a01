// build_atlas: a UV atlas for a closed 2-manifold triangle mesh (the proxy),
// paper §6.
//
// Inputs:  closed_mesh  closed, consistently oriented 2-manifold of any genus,
//                       possibly several components (the proxy).
//          options      texture size and padding, distortion budget, seam hints.
// Output:  AtlasResult  per-face corner UVs in [0,1]^2 (glTF convention), the
//                       chart of every face, and the atlas' diagnostics.
//
// Steps: seam hints -> forced seam edges (Dijkstra, §6 cost); segmentation
// into charts by normal-cone region growing (Lloyd iterations of variational
// shape approximation, charts added until every chart fits the normal budget;
// forced seams are never crossed); each chart is made a topological disk;
// LSCM then ARAP local/global per chart; a chart that flips, overlaps itself or
// exceeds the stretch budget is split in two and redone; optionally
// (merge_charts) neighbouring charts are merged again where the union still
// flattens within the budget (shorter seams); optionally (relax_seams) each
// boundary between two charts moves to its cheapest cut in a band around it
// (minimum cut, seams weighted per face); charts are scaled to
// one texel density, rotated to their minimal-area rectangle and packed into
// [0,1]^2 with padding by a bitmap packer (conservative rasters in 16 turns,
// lowest fit) and, for few charts, also a column (horizon) packer; the
// denser layout wins. With seam weights and alternative segmentation
// budgets, everything before the packing runs once per budget and the
// charts with the least weighted seam length are packed.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "soupuv/atlas/atlas.h"
#include "soupuv/mesh.h"
#include "soupuv/progress.h"
#include "soupuv/vec.h"

namespace soupuv::atlas {

// A user-drawn seam: consecutive points are joined along mesh edges (each
// point snaps to its nearest mesh vertex).
struct SeamHint {
  std::vector<Vec3> points;
};

struct AtlasOptions {
  int texture_size = 2048;   // texels along one side of the square texture
  double padding_px = 4;     // minimum gap between charts, in texels
  // Distortion budget: a chart whose area-weighted L2 stretch (Sander 2001,
  // chart scaled to its 3D area) exceeds this after ARAP is split.
  double max_stretch = 1.05;
  // Segmentation budget: largest angle between a face normal and its chart's
  // mean normal (degrees). Smaller gives more, flatter charts.
  double max_normal_deviation_deg = 40.0;
  // More segmentation budgets to try when seam_weight is given: the charts
  // are built for each (segmentation to relaxation), and the ones with the
  // least weighted seam length (seam_cost) are packed (merging and
  // relaxation make different things of each segmentation; the weighted
  // length predicts the soup pairs cut).
  std::vector<double> alternative_normal_deviations_deg;
  std::vector<SeamHint> seam_hints;
  // Seam hint cost weights (§6), dimensionless: the alpha (curvature) term is
  // scaled by the mean edge length so it competes with edge lengths, and the
  // beta (curvature change) term uses Laplacian magnitudes divided by their
  // maximum, also times the mean edge length.
  double alpha = 1.0;
  double beta = 1.0;
  int arap_iterations = 10;
  // Chart merging after flattening: neighbouring charts whose shared boundary
  // is mostly smooth (dihedral angle below merge_crease_deg) are merged when
  // the union still flattens as a disk without flips or overlap and within
  // max_stretch: fewer charts, shorter seams (see merge_charts.h).
  bool merge_charts = false;
  double merge_crease_deg = 60;
  // A merge is refused when the union would hold more than this fraction of
  // the surface or fill less than merge_min_fill of its minimal rectangle in
  // UV (big or ragged charts pack badly).
  double merge_max_area_fraction = 0.1;
  double merge_min_fill = 0.5;
  // A merge is also refused when a face of the union turns more than this
  // from the union's mean normal (degrees; 0 = no limit): a chart that wraps
  // around a thin part (a horn, an ear) leaves nothing for the pipeline's
  // chart fix to pull together when a soup triangle's corners land on both
  // sides of it.
  double merge_max_normal_deviation_deg = 0;
  // Stretch budget of a merged chart (and of the relaxation that moves its
  // seams); 0 = max_stretch. Above max_stretch it trades the atlas's own
  // stretch for fewer seams: the segmentation still splits at max_stretch,
  // only unions may flatten worse (the pipeline's candidates measure whether
  // the soup can afford it).
  double merge_max_stretch = 0;
  // Sweeps of descent on the L2 stretch itself after ARAP when a merge
  // flattens its union (0 = ARAP only): big merged charts flatten at lower
  // L2 than ARAP gives them, so more merges fit the budget.
  int merge_stretch_sweeps = 0;
  // Seam relaxation after flattening and merging: the boundary between two
  // neighbouring charts moves to the cheapest cut inside a band of
  // relax_band * sqrt(smaller chart's area) around it, where an edge costs
  // its length times the mean seam_weight of its two faces; kept only where
  // both charts still flatten within the budget (see relax_seams.h).
  bool relax_seams = false;
  double relax_band = 0.35;
  // A relaxed pair's joint L2 stretch may rise by at most this (the soup
  // wears the atlas's stretch: without the bound the stanford-bunny's L2
  // went 1.28 -> 1.32 in the pipeline).
  double relax_max_stretch_increase = 0.02;
  // A pair whose relaxed charts do not both flatten is retried with the band
  // halved, up to this many times.
  int relax_narrowings = 2;
  // Per-face seam weight (one per mesh face, > 0; empty = 1 everywhere): how
  // dear a seam through that face is. The pipeline weighs proxy faces by the
  // soup edges a seam there would cut.
  std::vector<double> seam_weight;
  // Read by the pipeline, not the atlas: with relax_seams on and no
  // seam_weight given, weigh the proxy faces by the soup's edge density
  // (pipeline/seam_weights.h); off, the relaxation only shortens seams.
  bool soup_seam_weights = true;
  // Packing: while utilisation is below `packing_split_below`, the largest
  // charts are halved and everything is packed again, at most
  // `packing_split_rounds` times (few big charts fill a square badly).
  // Not with merge_charts: halving would undo the merges.
  double packing_split_below = 0.72;
  int packing_split_rounds = 2;
  // Bitmap packer (after the column packer; the denser layout wins): turns
  // tried per chart (multiples of 360/pack_angles degrees from the chart's
  // minimal rectangle); 0 switches the bitmap packer off.
  int pack_angles = 16;
  int threads = 0;           // OpenMP threads; 0 = OpenMP's default
};

struct AtlasDiagnostics {
  int charts = 0;
  int faces = 0;
  double stretch_l2 = 0;     // area-weighted L2 stretch, 1 = isometric up to one scale
  double stretch_linf = 0;   // max singular value of the UV->3D map, same normalisation
  double angle_distortion_deg = 0;  // mean |UV angle - 3D angle| over corners
  int flipped = 0;           // faces with non-positive UV area
  double overlap = 0;        // texels covered twice / texels covered (raster at texture_size)
  double utilization = 0;    // UV area of all faces / area of [0,1]^2
  int segment_rounds = 0;    // seed-insertion rounds the segmentation took
  double segment_angle_deg = 0;   // the segmentation budget whose atlas was kept
  int segment_budgets_tried = 0;  // atlases built (1 + alternatives tried)
  int splits = 0;            // charts split for topology, flips, overlap or stretch
  int packing_splits = 0;    // flattened charts halved to pack tighter
  int chart_merges = 0;      // pairs of neighbouring charts merged after flattening
  int seam_edges = 0;        // mesh edges forced to be seams by the hints
  double seam_length = 0;    // total 3D length of mesh edges between two charts
  double seam_length_relative = 0;  // seam_length / sqrt(surface area): scale-free
  // Seam length weighted by seam_weight (equal to seam_length without
  // weights), before and after the relaxation, and what the relaxation did.
  double seam_cost_before_relax = 0, seam_cost = 0;
  int relaxed_pairs = 0, relaxed_faces = 0;
  double seconds = 0;         // wall clock
  double cpu_seconds = 0;     // process CPU time (all threads) during the build
  int pack_attempts = 0;      // packings tried by the scale searches
  std::string pack_method;    // "columns" or "raster": whose layout won
  double seconds_segment = 0, seconds_parameterize = 0, seconds_merge = 0, seconds_pack = 0;
  std::vector<std::string> warnings;
};

struct AtlasResult {
  Atlas atlas;
  AtlasDiagnostics stats;
  // Mesh edges (vertex pairs, smaller index first) the seam hints forced.
  std::vector<std::array<int, 2>> forced_seams;
  nlohmann::json diagnostics() const;
};

// Throws Error{invalid_input} for a mesh that is not a closed 2-manifold (an
// edge not shared by exactly two faces of opposite orientation), bad indices
// or non-finite coordinates; Error{no_triangles} for an empty mesh;
// Error{canceled} through progress.
AtlasResult build_atlas(const TriMesh& closed_mesh, const AtlasOptions& options,
                        Progress& progress);

}  // namespace soupuv::atlas
