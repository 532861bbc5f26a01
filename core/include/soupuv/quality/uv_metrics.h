// How good a soup's texture mapping is: the figures the targets name.
//
// Input : a soup, one UV per triangle corner (glTF convention, [0,1]^2 wanted),
//         and the adjacency that says which soup triangles were neighbours
//         before the soup was split (from a welded original with the same
//         triangle order, or by welding the soup within a tolerance).
// Output: coverage, flipped fraction, area-weighted L2 stretch (Sander et al.
//         2001), continuity (noise-aware and plain 1-texel) and UV islands.
//
// Degenerate triangles (as Sander et al.: the stretch is the map from UV onto
// the surface, weighted by 3D area):
//   - zero 3D area: no weight and no map — left out of every figure but
//     coverage (a 3D sliver of tiny but nonzero area mapped faithfully has
//     stretch ~1 and tiny weight: it cannot blow the figure up);
//   - zero (or < 1e-6 of the mean ratio) UV area with 3D area: stretch is
//     infinite, so it is counted as flipped, not added to the L2 sum;
//   - flipped with nonzero UV area: counted as flipped AND its singular
//     values enter the L2 sum (a nearly collapsed fold is real distortion
//     and stays visible there; causes.stretch_l2_unflipped leaves them out).
#pragma once

#include <array>
#include <vector>

#include <nlohmann/json.hpp>

#include "soupuv/geometry/weld.h"
#include "soupuv/soup.h"

namespace soupuv::quality {

using CornerUvs = std::vector<std::array<Vec2, 3>>;  // one entry per soup triangle

struct UvMetricsOptions {
  // Texel size for the continuity threshold: 1 / texture_size.
  int texture_size = 1024;
  // UV units per unit of 3D length (the atlas's global texel scale). 0: derive
  // it from the map itself, sqrt(total UV area / total 3D area).
  double uv_per_length = 0;
};

struct UvMetrics {
  size_t triangles = 0;
  double coverage = 0;          // corners with finite UVs in [0,1]^2
  size_t flipped = 0;           // UV orientation against the dominant one, or collapsed
  double flipped_fraction = 0;
  double stretch_l2 = 0;        // area-weighted, normalised so 1 = isometric up to scale
  double stretch_linf = 0;      // largest per-triangle singular-value ratio to the scale
  // Companions to stretch_l2 (which stays the target figure), to read it by:
  // area-weighted median of the per-triangle stretch (robust to a few UV
  // slivers), and the share of the squared L2 sum from the worst 1 % of
  // triangles (near 1: the figure is made by a handful of slivers).
  double stretch_median = 0;
  double stretch_l2_worst1pct_share = 0;
  size_t adjacent_pairs = 0;
  double continuity = 0;        // pairs within 1 texel + 2 x (copies' 3D distance) in UV
  double continuity_1texel = 0; // pairs within 1 texel
  size_t islands = 0;           // components of triangles joined by continuous edges
  double uv_per_length = 0;     // the scale used
  // As eval/uvmetrics.py (quality/uv_overlap.h): UV area of the triangles
  // inside [0,1]^2, and the share of their rasterised area covered twice.
  double utilisation = 0;
  double overlap = 0;
};

UvMetrics uv_metrics(const Soup& soup, const CornerUvs& uvs,
                     const std::vector<geometry::AdjacentPair>& adjacency,
                     const UvMetricsOptions& options = {});

// Area-weighted L2 stretch over the triangles with include[t] != 0, at a
// given global scale (UvMetrics::uv_per_length convention: the normalisation
// the full figure used), so parts of a map can be compared with the whole.
double stretch_l2_subset(const Soup& soup, const CornerUvs& uvs,
                         const std::vector<uint8_t>& include, double scale);

// The adjacency for metrics: exact from `original` (a welded mesh with the
// same triangle order as `soup`), else by welding the soup within
// `weld_tolerance` (absolute).
std::vector<geometry::AdjacentPair> metric_adjacency(const Soup& soup, const Soup* original,
                                           double weld_tolerance);

// Diagnostics fields: coverage, flipped_fraction, stretch_l2, continuity, ...
// (continuity fields are left out when there are no adjacent pairs).
nlohmann::json to_json(const UvMetrics& m);

}  // namespace soupuv::quality
