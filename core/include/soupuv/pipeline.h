// run_map: the one call the CLI and the server worker make — a loaded asset in,
// three UVs per soup triangle and the diagnostics out (paper Fig. 3).
//
//   soup ──┬─► [refine intersections] ─► charge ─► trace (+ side choice) ─┐
//          │                                                               ├─► transfer ─► UVs ─► metrics
//          └─► proxy ─► atlas ─────────────────────────────────────────────┘
//
// The two branches run on two threads, each with half the thread budget.
// Charges and field lines are cached by (soup geometry, field parameters,
// algorithm version): a re-run with other proxy or atlas parameters reuses
// them — the monopole field does not depend on the proxy (§9).
//
// method = box runs the tri-planar baseline instead, through the same metrics
// and diagnostics, so the two methods can be compared field by field.
//
// Errors: soupuv::Error (no_triangles, invalid_input, canceled through
// progress, internal); the diagnostics of a failed run are not returned.
#pragma once

#include <array>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "soupuv/atlas/atlas.h"
#include "soupuv/atlas/build_atlas.h"
#include "soupuv/field/field.h"
#include "soupuv/io/asset.h"
#include "soupuv/progress.h"
#include "soupuv/proxy/proxy.h"
#include "soupuv/transfer/transfer.h"
#include "soupuv/uvsolve/soup_uv_solve.h"

namespace soupuv {

namespace cache { class Store; }

enum class MapMethod { field, box };

// The atlas the field method asks for: fewer, larger charts than the atlas's
// own defaults. Every chart seam cuts the soup triangles whose corners land
// on both sides of it (§8 moves them onto one chart), so seam length, not
// chart flatness, bounds continuity. Measured on spot (offset 0.03,
// continuity with the original's adjacency): 40 deg, 86 charts -> 0.78;
// 70 deg, 27 charts -> 0.87. On top of that the charts are merged (no size
// limit, within a 120 deg normal cone): 3-9 charts instead of 15-34, and
// continuity +0.01 .. +0.05 on every sample (numbers in map_defaults.cpp).
atlas::AtlasOptions map_atlas_defaults();

// The proxy the field method asks for: the automatic offset, but its ladder
// starts at 3 % of the diagonal. A tighter proxy is finer and bends more, so
// the atlas cuts it into more charts, and the seams cost more continuity
// than the tighter fit gains. Measured on spot: offset 0.015 -> 12,138 proxy
// triangles, 44 charts, continuity 0.918; 0.03 -> 3,392, 25, 0.925.
proxy::ProxyOptions map_proxy_defaults();

struct MapOptions {
  MapMethod method = MapMethod::field;
  proxy::ProxyOptions proxy = map_proxy_defaults();
  atlas::AtlasOptions atlas = map_atlas_defaults();
  // The field library's own accuracy (charge tolerance 1e-6, tracer p = 7).
  // Measured against tolerance 1e-4 / p = 5 (`soupuv-bench pipeline --only
  // accuracy`, no UV repair, offset 0.03, loaded machine): median corner UV
  // shift 0.001-0.002 texel, but corners moved > 1 texel: suzanne 0.3 %,
  // spot 0.01 %, fandisk 1.2 % (p99 5 texels), fandisk continuity 0.9551 ->
  // 0.9532; CPU 10.5 -> 5.9 s (suzanne), 10.3 -> 9.5 (spot), 28.2 -> 25.1
  // (fandisk). The saving is small where the soup is large, so not taken.
  field::ChargeOptions charge;
  // trace.stop_radius = 0 (and an empty trace.stop_box) here means: lines
  // stop outside the soup's box grown by 1.25 x the proxy reach, once they
  // are surely past any proxy (field_branch.h), not at the tracer's own far
  // default.
  field::TraceOptions trace;
  transfer::TransferOptions transfer;

  // §12.1: split soup triangles along their intersections before charging
  // (only original corners are traced; the writer keeps the original
  // triangles).
  bool refine_intersections = true;
  // §12.4: one traced side per welded component (field/orient.h).
  bool orient_sides = true;
  // Copies of one welded position share one field line (start at their mean,
  // along their mean oriented normal); false: one line per corner from its
  // own triangle, as in the paper.
  bool share_lines = true;
  // Without a cache, field lines end at their first crossing of the proxy
  // (§7.6: the hit is all the transfer uses; the trace waits for the proxy,
  // which the proxy branch builds long before the charge is solved). With a
  // cache they run on to the reach box, so that the cached lines serve any
  // proxy offset (the field is cached per mesh). The map is the same either
  // way. false: always to the reach box.
  bool stop_lines_at_proxy = true;
  // §8 with neighbours: a triangle across a chart seam prefers the chart its
  // (welded) neighbours use (transfer/chart_fix.h); false: the paper's
  // per-triangle rule.
  bool chart_fix_neighbours = true;
  // Welding for the neighbour graph (orientation, continuity when no original
  // is given): corners closer than weld_tolerance * bounding-box diagonal, and
  // closer than weld_edge_fraction * their triangles' shortest edge (never two
  // corners of one triangle). Measured on spot: fraction 0.3 left 510 of the
  // 8,784 original neighbour pairs unwelded (221 components, 3,623 lines);
  // 1.0 finds them (1 component, 2,938 lines, continuity 0.919 -> 0.925).
  double weld_tolerance = 2e-3;
  double weld_edge_fraction = 1.0;
  // The §8 neighbours and the UV solve weld by matching edges instead
  // (geometry::weld_by_edges), within edge_weld_tolerance * diagonal (the
  // shared soups' copies lie up to 3e-3 apart). Welding corners joined
  // distinct vertices where the noise reaches the edge length (teapot rim:
  // 409 corners) and the previous chain's UV repair could not start there;
  // measured with it and --original (loaded machine), geometry::weld_corners ->
  // geometry::weld_by_edges, continuity /
  // flipped % / L2: teapot 0.935 / 1.31 / 1.61 -> 0.938 / 0.97 / 1.35,
  // suzanne 0.906 / 1.14 / 3.47 -> 0.902 / 0 / 2.32, spot 0.959 / 0 / 1.18
  // -> 0.958 / 0 / 1.18, fandisk 0.979 / 0.02 / 1.36 -> 0.979 / 0.05 /
  // 1.36 (-> 0 / 1.17 with the repair's island start; docs/tuning.md).
  bool weld_by_edges = true;
  double edge_weld_tolerance = 4e-3;
  // The shared lines' seeds weld by matching edges too (edge_weld_tolerance),
  // then by corner distance (weld_tolerance) for the copies no edge joined
  // (geometry::extend_weld); false: corner distance alone. Teapot: original
  // neighbour pairs whose copies start different lines 448 -> 225 of 9,400
  // (edges alone 269). With the previous UV chain (docs/tuning.md), one
  // binary, loaded machine (`soupuv map --original`; CLI --seed-weld-corners
  // --no-reweld --strict-retry 1.2 --no-grow-while-bad gives session 5's
  // pipeline; edge fraction 1 below, no growth), continuity /
  // flipped % / L2: teapot 0.9441 / 0.174 / 1.105 -> 0.9521 / 0.316 / 1.119,
  // spot 0.9669 -> 0.9671, fandisk 0.9800 -> 0.9799, stanford-bunny 0.9868 /
  // 0 / 1.281 -> 0.9872 / 0 / 1.280, suzanne and the welded glTF samples
  // unchanged; 100k noisy torus (`soupuv-bench pipeline --only torus-100k`)
  // 0.9857 / 0 / 1.115 -> 0.9876 / 0.001 / 1.153: the seeds share more, but
  // join distinct vertices more often where the noise reaches the edge
  // length, and two repair patches fail (one flipped sliver; L2 without it
  // 1.132).
  bool seed_weld_by_edges = true;
  // The edge fraction of that distance weld on top (0: weld_edge_fraction):
  // 0.5 joins fewer distinct vertices where the noise reaches the edges.
  // One binary, loaded machine, 1.0 -> 0.5: teapot 0.9541 / 0.127 % / 1.103
  // -> 0.9553 / 0.063 % / 1.098 (neighbour pairs on different lines 225 ->
  // 243, but fewer false joins for the repair to undo), 100k torus
  // continuity 0.98764 -> 0.98808 (L2 1.152 both); spot, suzanne, fandisk,
  // stanford-bunny unchanged.
  double seed_weld_edge_fraction = 0.5;
  // Seam relaxation (atlas.relax_seams, on in map_atlas_defaults) runs only
  // when the soup has at most this many triangles per proxy face (0: always).
  // A seam of length L cuts about L / h soup pairs (h = soup edge length), so
  // shorter seams pay on coarse soups; on fine ones continuity is already
  // ~0.99 and the relaxed charts stretch a little more (stanford-bunny, 19
  // soup triangles per proxy face: continuity 0.987 -> 0.989, L2 1.281 ->
  // 1.312, over the 1.3 target; map_defaults.cpp has the figures).
  double relax_max_soup_per_proxy_face = 8;

  // After transfer, the soup UV solve (uvsolve/soup_uv_solve.h): the map is
  // cut where it is discontinuous, folds or overlaps, solved for low
  // distortion without flips and packed at one density.
  uvsolve::SoupUvOptions uv_solve;

  int threads = 0;             // total budget; 0 = OpenMP default
  cache::Store* cache = nullptr;  // shared, thread-safe; nullptr = no cache

  // Continuity reference: a welded mesh with the soup's triangle order
  // (e.g. NAME-soup.original.glb); nullptr = weld the soup.
  const Soup* original = nullptr;
  int metrics_texture_size = 1024;

  bool keep_debug = false;     // fill MapResult::debug (proxy, atlas, lines)
};

using debug_bytes = std::vector<uint8_t>;

struct MapDebug {
  proxy::ProxyMesh proxy;
  atlas::Atlas atlas;
  field::FieldLines lines;
};

struct MapResult {
  std::vector<Vec2> corner_uvs;   // 3 per soup triangle (glTF convention)
  nlohmann::json diagnostics;     // proto/diagnostics.schema.json
  MapDebug debug;                 // when keep_debug
};

MapResult run_map(const io::Asset& asset, const MapOptions& options,
                  Progress& progress = Progress::none());

// Same, for a bare soup (tests, benchmarks).
MapResult run_map(const Soup& soup, const MapOptions& options,
                  Progress& progress = Progress::none());

// Debug outputs (from MapResult::debug), as file contents:
// the proxy wearing its atlas and `texture_png` (a PNG image) as a GLB;
debug_bytes proxy_debug_glb(const MapDebug& debug, const std::vector<uint8_t>& texture_png);
// the field lines as one LINES primitive (at most max_lines, evenly sampled);
debug_bytes field_lines_glb(const field::FieldLines& lines, size_t max_lines = 30000);

}  // namespace soupuv
