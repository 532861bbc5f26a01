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
#include "soupuv/transfer/island_relax.h"
#include "soupuv/transfer/transfer.h"
#include "soupuv/transfer/uv_repair.h"
#include "soupuv/transfer/uv_reweld.h"
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

// One alternative (proxy, atlas) for the field method. The field does not
// depend on the proxy or the atlas (§9), so on small soups run_map can try
// several against the one cached field and keep the variant whose measured
// quality (weld-inferred continuity within the flipped / stretch targets) is
// best. proxy_offset_fraction > 0 replaces the proxy's automatic offset by
// that fraction of the soup's diagonal; 0 keeps MapOptions::proxy.
struct MapCandidate {
  std::string name;
  atlas::AtlasOptions atlas;
  double proxy_offset_fraction = 0;
};

// The candidates, the first being {"default", map_atlas_defaults(), 0}.
// map_defaults.cpp says why each is on the list.
std::vector<MapCandidate> map_candidates();

// "NAME:K=V,K=V" -> a candidate on top of map_atlas_defaults(), for the CLI's
// --candidate and the benches' A/B runs. Keys: angle (segmentation budget,
// deg), alt_angle (one more budget), no_alt_angles, stretch, merge_cone,
// merge_area, merge_fill, merge_stretch, merge_sweeps, relax (0/1), relax_band, relax_stretch, offset
// (proxy_offset_fraction). Throws Error{invalid_input} on anything else.
MapCandidate parse_map_candidate(const std::string& spec);

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
  // Experimental, off: also trace probe points inside the kept piece of each
  // cut triangle and extrapolate its other corners' UVs from them
  // (transfer/intersect.h). On the Fig. 19 planes it made the cut triangles
  // worse (worst UV/3D edge ratio 25 against 2.2 without), so it stays off.
  bool cut_probe_extrapolation = false;
  // §12.4: one traced side per welded component (transfer/orient.h).
  bool orient_sides = true;
  // Copies of one welded position share one field line (start at their mean,
  // along their mean oriented normal); false: one line per corner from its
  // own triangle, as in the paper.
  bool share_lines = true;
  // §8 with neighbours: a triangle across a chart seam prefers the chart its
  // (welded) neighbours use (transfer/chart_fix.h); false: the paper's
  // per-triangle rule.
  bool chart_fix_neighbours = true;
  // Local UV repair after transfer (transfer/uv_repair.h): a documented
  // post-process, not the paper's; only the UV vertices of flipped,
  // collapsed or badly stretched triangles move. On by default: it cuts
  // flips and the L2 stretch on every sample for a continuity change of at
  // most -0.0014. Measured (offset auto, --original, before -> after) spot
  // flipped 0.68 -> 0.56 %, L2 3.35 -> 3.19, continuity 0.9273 -> 0.9269;
  // suzanne 9.7 -> 4.5 %, 5.85 -> 4.49, 0.8648 -> 0.8634; teapot 2.09 ->
  // 1.50 %, 9.24 -> 3.07, 0.8950 -> 0.8949; fandisk 1.27 -> 0.91 %, 17.5 ->
  // 16.5, 0.9551 -> 0.9551; 100k torus (an earlier build) 0.34 -> 0.05 %,
  // 13.2 -> 1.70, 0.9797 -> 0.9800. Session 4 added the untangling start
  // (patches at open chart borders and chart islands that no other start
  // could begin); `soupuv-bench pipeline --only samples`, session 3's repair
  // -> with untangling, flipped % and L2: suzanne 3.82 -> 1.24, 4.39 ->
  // 3.58; spot 0.55 -> 0, 2.40 -> 1.15; teapot 1.46 -> 1.30, 3.05 -> 2.09;
  // fandisk 0.90 -> 0.02, 16.1 -> 1.17; stanford-bunny 0.56 -> 0, 6.97 ->
  // 1.26; Duck 1.02 -> 0.09, 43.9 -> 1.11; CesiumMan 0.32 -> 0, 45.7 ->
  // 1.21; Fox 2.95 -> 0, 2.42 -> 1.14; bunny .drc 0.22 -> 0, 100 -> 1.21;
  // continuity within -0.0006 everywhere. Rows of `soupuv-bench pipeline
  // --only samples` carry before_repair; --no-uv-repair turns it off.
  bool uv_repair = true;
  transfer::UvRepairOptions repair;
  // The repair also takes triangles whose corners landed on two charts (§8
  // could not join them) and moves the odd corner onto the triangle's chart
  // (the one two corners share) — UvRepairOptions::corner_chart.
  bool repair_split_triangles = true;
  // Welding for the neighbour graph (orientation, continuity when no original
  // is given): corners closer than weld_tolerance * bounding-box diagonal, and
  // closer than weld_edge_fraction * their triangles' shortest edge (never two
  // corners of one triangle). Measured on spot: fraction 0.3 left 510 of the
  // 8,784 original neighbour pairs unwelded (221 components, 3,623 lines);
  // 1.0 finds them (1 component, 2,938 lines, continuity 0.919 -> 0.925).
  double weld_tolerance = 2e-3;
  double weld_edge_fraction = 1.0;
  // The §8 neighbours and the UV repair weld by matching edges instead
  // (quality::weld_by_edges), within edge_weld_tolerance * diagonal (the
  // shared soups' copies lie up to 3e-3 apart). Welding corners joined
  // distinct vertices where the noise reaches the edge length (teapot rim:
  // 409 corners) and the repair could not start there; measured with
  // --original (loaded machine), weld_corners -> weld_by_edges, continuity /
  // flipped % / L2: teapot 0.935 / 1.31 / 1.61 -> 0.938 / 0.97 / 1.35,
  // suzanne 0.906 / 1.14 / 3.47 -> 0.902 / 0 / 2.32, spot 0.959 / 0 / 1.18
  // -> 0.958 / 0 / 1.18, fandisk 0.979 / 0.02 / 1.36 -> 0.979 / 0.05 /
  // 1.36 (-> 0 / 1.17 with the repair's island start, uv_repair.h).
  bool weld_by_edges = true;
  double edge_weld_tolerance = 4e-3;
  // The shared lines' seeds weld by matching edges too (edge_weld_tolerance),
  // then by corner distance (weld_tolerance) for the copies no edge joined
  // (quality::extend_weld); false: corner distance alone. Teapot: original
  // neighbour pairs whose copies start different lines 448 -> 225 of 9,400
  // (edges alone 269). With uv_reweld and the 1.05 strict retry below, one
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
  // The repair's UV vertices are the shared lines' groups (one line, one UV
  // vertex per chart) instead of weld_by_edges' vertices. Off: those groups
  // hold the seeds' false joins, which the repair then cannot unfold (teapot,
  // reweld on, retry 1.2: 0.9448 vs 0.9467 with the edge weld; without the
  // retry 0.9571 but 1.38 % flipped).
  bool repair_weld_lines = false;
  // After the repair: copies of one line left at different UVs on one chart
  // are joined again where nothing folds (transfer/uv_reweld.h). Teapot
  // (retry 1.05) 0.9517 / 0.348 % -> 0.9521 / 0.316 %; 100k torus
  // continuity 0.98746 -> 0.98762, L2 unchanged.
  bool uv_reweld = true;
  transfer::UvReweldOptions reweld;
  // When repair patches failed, the repair can run once more on their
  // triangles with a strict edge weld (an edge whose second-best partner is
  // within this factor of its best stays unmatched; <= 1: no retry). Off:
  // it trades continuity for flips. Teapot (--original, loaded machine, one
  // binary), cont / flipped % / L2: off 0.942 / 1.14 / 1.72, 1.2 -> 0.937 /
  // 0.19 / 1.13, 2 -> 0.925 / 0.02 / 1.13. CLI --strict-retry F. On (1.2)
  // since session 5: with the relaxed seams, teapot 0.949 / 1.16 / 1.30 ->
  // 0.945 / 0.17 / 1.11 (1.5: 0.939 / 0 / 1.10) — it misses continuity 0.95
  // either way, and flipped triangles are what a viewer sees; samples
  // without failed patches are untouched (one binary, quiet machine).
  // Session 6, with the edge-welded seeds and the re-weld (teapot, one
  // binary, loaded machine), cont / flipped % / L2 by ratio: 1.02 0.9536 /
  // 0.82 / 1.25, 1.03 0.9531 / 0.71 / 1.25, 1.05 0.9521 / 0.32 / 1.12,
  // 1.08 0.9502 / 0.24 / 1.11, 1.2 0.9467 / 0.24 / 1.11: 1.05 is the
  // loosest that keeps flips under 0.5 %.
  double repair_strict_retry = 1.05;
  // Island relaxation after the repair and the re-weld (transfer/
  // island_relax.h): every UV island re-flattened as a whole (SLIM on the
  // symmetric Dirichlet energy), its cuts kept; an island is accepted only
  // if its L2 stretch drops with no new flip and no new overlap. Islands
  // are built on the soup's corner weld (weld_tolerance, weld_edge_fraction:
  // the candidate choice's) and its edge weld (copies the corner weld
  // missed; without it suzanne lost 4 continuous pairs of the original's,
  // 0.9686 -> 0.9659). Runs on soups of at most
  // island_relax_max_triangles (0: any size): the gate of the candidate
  // search, whose soups it is for. Ungated on the 100k torus (`soupuv-bench
  // pipeline --only torus-100k --island-max-triangles 0`, loaded machine) it
  // gains nothing (L2 1.15247 -> 1.15247: its islands of 13k-28k triangles
  // are all rejected, "flipped") and costs 5.1 s of a 33.0 s first run and
  // 4.1 s of an 8.4 s re-run (3.9x, under the 5x target); gated: 0 s. Measured on Fox (`soupuv-bench pipeline
  // --only Fox`, loaded machine), per candidate L2 before -> after: nc120d
  // 1.298 -> 1.213, nc150d 1.413 -> 1.302, atlas's o37d 1.474 -> 1.292, so
  // o37d becomes admissible and is chosen: continuity 0.9236 -> 0.9537.
  // Costs 0.1-0.4 s per candidate on Fox.
  bool island_relax = true;
  transfer::IslandRelaxOptions island;
  size_t island_relax_max_triangles = 20000;

  // Seam relaxation (atlas.relax_seams, on in map_atlas_defaults) runs only
  // when the soup has at most this many triangles per proxy face (0: always).
  // A seam of length L cuts about L / h soup pairs (h = soup edge length), so
  // shorter seams pay on coarse soups; on fine ones continuity is already
  // ~0.99 and the relaxed charts stretch a little more (stanford-bunny, 19
  // soup triangles per proxy face: continuity 0.987 -> 0.989, L2 1.281 ->
  // 1.312, over the 1.3 target; map_defaults.cpp has the figures).
  double relax_max_soup_per_proxy_face = 8;

  // Candidates chosen by measured quality (pipeline/candidates.h). The first
  // entry stands for this run's own `proxy` and `atlas` (only its name is
  // read); every further entry is landed against the same field lines and
  // the one with the best weld-measured continuity within the two bounds
  // below is kept (the first when none is). Fewer than two entries: one run,
  // exactly as without a search. The search runs only on soups of at most
  // candidates_max_triangles and at most relax_max_soup_per_proxy_face soup
  // triangles per face of the first proxy (0: no coarseness gate), so the
  // fine soups (bunnies, 100k torus) keep one run. Measured cost of the
  // search with atlas's five candidates (`soupuv-bench pipeline --only
  // samples`, loaded machine, wall): Fox, Duck, Box +8.3 s, suzanne +8.5,
  // CesiumMan +10.9, spot +13.2, fandisk +16.1, teapot +42 (its repair is
  // slow) on runs of 10-55 s; in exchange continuity rose on every sample
  // it ran on (suzanne 0.9505 -> 0.9686, Fox 0.868 -> 0.924, ...). The
  // 20,000 bound keeps the search off soups whose own run is already long;
  // a small soup's re-run repeats the search (its proxy changed).
  std::vector<MapCandidate> candidates = map_candidates();
  size_t candidates_max_triangles = 20000;
  double candidate_max_flipped = 0.005;
  double candidate_max_stretch_l2 = 1.3;

  // The soup UV solve (uvsolve/soup_uv_solve.h): after transfer, the map is
  // cut where it is discontinuous, folds or overlaps, solved for low
  // distortion without flips and packed at one density. When on, it
  // replaces the repair chain above (uv_repair, reweld, island_relax) and
  // the candidate search.
  bool soup_uv_solve = true;
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
