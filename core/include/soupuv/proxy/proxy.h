// build_proxy: the offset-surface proxy of a triangle soup (paper §5, §9.1).
//
// Input:  a Soup (any triangles, shared or not, open or closed).
// Output: ProxyResult.proxy — the level set d(x) = o of the unsigned distance to
//         the soup, extracted from a sparse narrow-band grid by marching
//         cubes (asymptotic decider), coarsened by our manifold-keeping edge
//         collapse to about the target edge length, inner components
//         (cavities) dropped, evened out by CGAL isotropic remeshing, Taubin
//         smoothed and lifted back to d = o where it sank. Always closed,
//         2-manifold, outward-oriented; every check is measured and reported
//         in ProxyResult (never assumed).
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "soupuv/progress.h"
#include "soupuv/proxy/proxy_mesh.h"
#include "soupuv/soup.h"

namespace soupuv::proxy {

enum class OffsetMode {
  absolute,   // offset is a length in soup units
  relative,   // offset is a fraction of the bounding-box diagonal
  automatic,  // the tightest rung of `ladder` giving one enclosing outer component
};

struct ProxyOptions {
  OffsetMode offset_mode = OffsetMode::automatic;
  double offset = 0.02;  // absolute length, or fraction of the diagonal (relative)
  // Fractions of the diagonal tried by `automatic`, tightest first; the first
  // that gives one outer component enclosing the soup wins. It starts at 1 %:
  // with the target edge length = o that is a few 10k triangles for a compact
  // shape (0.5 % gave 100k+ and a 300-cell grid, more than atlas and transfer
  // need), and Table 1 shows 1 % already follows the soup closely.
  std::vector<double> ladder = {0.01, 0.015, 0.02, 0.03, 0.05, 0.08, 0.12};

  // Cells along the longest axis of the soup's bounding box. 0 = from the §9.1
  // sampling argument: cell size o/2 (Table 1: 1 % offset -> 200 samples),
  // clamped to [min_resolution, max_resolution].
  int resolution = 0;
  int min_resolution = 16;
  int max_resolution = 512;

  // Level-set extraction: marching cubes with the asymptotic decider (about 2
  // triangles per cell), or marching tetrahedra (about 6; kept as the
  // simpler, table-free reference).
  bool marching_cubes = true;
  // Prune the narrow band to cells that can touch the outer shell (flood fill
  // from the grid border at every level), so the cavity of a closed soup is
  // never refined, extracted or collapsed. The component split stays as the
  // safety net; false builds every shell and drops the inner ones afterwards.
  bool prune_cavities = true;

  // Remeshing to a target edge length: our short-edge collapse (link
  // condition, no flips), then remesh_iterations of CGAL PMP isotropic
  // remeshing (0 = collapse only); target 0 = auto
  // (the offset o: the offset surface bends no tighter than radius o on its
  // convex parts). Verified afterwards; undone with a warning if it broke a check.
  bool remesh = true;
  double target_edge_length = 0;
  int remesh_iterations = 3;
  // Face budget of the remeshed proxy, estimated right after marching cubes
  // (the level set's area tiled at the target edge length). Over it, the
  // automatic ladder moves to its next rung and an explicit offset is refused
  // with an invalid_input error. The atlas's cost grows faster than the
  // proxy's size (a user's 0.5 % offset on a box, 280k faces, ran for over
  // 15 minutes); the default ladder's proxies are 2.4k-8k triangles on the
  // corpus (docs/tuning.md, "The proxy's face budget"). 0 = none.
  size_t max_triangles = 50000;

  // Taubin lambda|mu smoothing (no shrinkage). 0 = off.
  int smoothing_iterations = 10;
  // Rounds of lifting vertices that sank below d = o (by collapse and
  // smoothing) back along their normals, a quarter edge at most per round.
  // 0 = off.
  int lift_iterations = 2;

  // Self-intersection test (CGAL PMP); costs about as much as the remeshing.
  bool check_self_intersections = true;

  int threads = 0;  // OpenMP threads; 0 = OpenMP default
};

struct ProxyResult {
  ProxyMesh proxy;

  // Diagnostics, all measured on the final proxy.
  bool closed = false;           // every edge has exactly two faces
  bool manifold = false;         // closed edges and every vertex has one fan
  bool outward = false;          // every outer component has positive volume
  long euler = 0;                // V - E + F of the outer components
  int genus = 0;                 // sum over outer components of (2 - chi) / 2
  int outer_components = 0;
  int inner_components = 0;      // dropped (cavities inside another component)
  bool encloses = false;         // every soup vertex is inside the proxy
  size_t soup_vertices_outside = 0;
  double min_distance = 0;       // min over proxy vertices and face centroids of d(x, soup) (capped at 2 o)
  double min_distance_ratio = 0; // min_distance / offset (>= 0.5 required)
  bool self_intersections_checked = false;
  bool self_intersections = false;
  size_t triangles = 0;
  size_t vertices = 0;
  size_t raw_triangles = 0;      // straight out of marching cubes / tetrahedra
  size_t collapsed_triangles = 0;  // after our short-edge collapse, before CGAL remeshing
  double estimated_triangles = 0;  // the face budget's estimate of `triangles`, from the level set's area
  size_t surface_cells = 0;      // leaf cells of the narrow band
  size_t pruned_cells = 0;       // band cells dropped as cavity, all levels
  size_t distance_evaluations = 0;
  double offset = 0;             // absolute offset used
  double offset_fraction = 0;    // offset / bounding-box diagonal
  int resolution = 0;
  double cell_size = 0;
  std::vector<double> ladder_tried;  // fractions tried by `automatic`
  double seconds = 0;
  double seconds_grid = 0, seconds_extract = 0, seconds_remesh = 0,
         seconds_smooth = 0, seconds_checks = 0;
  double seconds_decimate = 0;   // the short-edge collapse part of seconds_remesh (ours, not CGAL's)
  std::vector<std::string> warnings;

  bool ok() const {
    return closed && manifold && outward && encloses && outer_components >= 1 &&
           !self_intersections;
  }
  nlohmann::json diagnostics() const;
};

// Throws Error{no_triangles} for an empty soup, Error{invalid_input} for bad
// options, Error{canceled} through progress.
ProxyResult build_proxy(const Soup& soup, const ProxyOptions& options,
                        Progress& progress = Progress::none());

}  // namespace soupuv::proxy
