// The field branch of run_map: [intersection refinement] -> charge -> trace
// with one traced side per welded component, cached by content.
//
// Input : the soup, its geometry hash, options, an optional cache.
// Output: one field line per soup corner (only original corners are traced,
//         whatever the refinement added) and the branch's diagnostics.
#pragma once

#include <functional>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "soupuv/cache/store.h"
#include "soupuv/field/field.h"
#include "soupuv/geometry/weld.h"
#include "soupuv/mesh.h"
#include "soupuv/progress.h"
#include "soupuv/proxy/proxy.h"
#include "soupuv/soup.h"

namespace soupuv::pipeline {

struct FieldBranchOptions {
  field::ChargeOptions charge;
  field::TraceOptions trace;
  bool refine_intersections = true;
  bool orient_sides = true;
  // Copies of one welded position share one field line (shared_seeds.h);
  // false: one line per corner from its own triangle (the paper's seeding).
  bool share_lines = true;
  double weld_tolerance = 0;       // absolute
  double weld_edge_fraction = 0.3;
  // > 0 (absolute): the shared lines' seeds weld by matching edges first
  // (geometry::weld_by_edges at this tolerance), then by corner distance on
  // top (geometry::extend_weld, weld_tolerance / weld_edge_fraction), so that
  // copies of a vertex start one line where position alone is ambiguous.
  // 0: corner distance alone. The orientation uses the same weld.
  double seed_edge_weld_tolerance = 0;
  // ... and the distance weld on top of it then uses this edge fraction
  // (geometry::weld_corners' edge_fraction); 0: weld_edge_fraction.
  double seed_edge_fraction = 0;
  int threads = 1;
  // How far from the soup any proxy the pipeline may build can lie
  // (proxy_reach()); > 0 while trace.stop_radius is 0 and trace.stop_box is
  // empty: lines end once they leave the soup's bounding box grown by
  // kReachMargin * proxy_reach (stop_box_for). A point out there is farther
  // than that from every soup point, so the line has crossed every such
  // proxy: the lines are cached for any proxy within the reach, and a re-run
  // asking for a farther offset gets a larger reach, a new key, a re-trace.
  // Why a box and not the sphere of half the diagonal + reach: past the
  // near-surface steps a line travels at the full step, and each step enters
  // fresh FMM target cells (new local expansions for few points). Measured
  // alone (`soupuv-bench field-branch`, 100k noisy torus, 50,668 shared
  // lines, 2 threads, loaded machine, tracer of 0e23ace): 0.75-diagonal
  // sphere 4.63 M evaluations / 42.5 s CPU; box at reach 0.12 diagonals
  // 2.90 M / 27.3 s CPU; the same UVs (run_map with the tracer of 8cae232:
  // median shift 0, 0.02 % of corners > 1 texel, continuity 0.98565 ->
  // 0.98564, hit fraction and fallbacks equal).
  double proxy_reach = 0;
  // Set: called once, after the charges, before the trace (it may wait for
  // the proxy branch). A mesh it returns ends each line at its first
  // crossing of it (TraceOptions::stop_crossing): the transfer lands lines
  // there, so the steps beyond were wasted. The lines' cache key then names
  // the mesh (a new proxy is a re-trace; the charges stay cached). nullptr,
  // or unset: lines run to the reach box (proxy_reach) and serve any proxy.
  // The mesh must live until run_field_branch returns.
  std::function<const TriMesh*()> stop_surface;
};

// Margin over the reach: the proxy is lifted to its offset o, but remeshing
// and smoothing leave parts of it a little beyond o.
inline constexpr double kReachMargin = 1.25;

// The farthest offset from the soup of any proxy built with `options`: its
// own offset, but never less than the largest rung of its ladder (so every
// offset up to that shares one set of cached lines).
double proxy_reach(const Soup& soup, const proxy::ProxyOptions& options);

// The box outside which a line has crossed every proxy within `reach`.
Box3 stop_box_for(const Soup& soup, double reach);

struct FieldBranchResult {
  field::FieldLines lines;
  // With shared lines: the line of every soup corner (lines.corner names one
  // corner per line). Empty: line i belongs to corner lines.corner[i] alone.
  std::vector<uint32_t> line_of_corner;
  nlohmann::json charge;        // charge diagnostics (solver, history, ...)
  nlohmann::json trace;         // trace diagnostics (ends, steps, ...)
  nlohmann::json orient;        // side choice
  nlohmann::json intersections; // refinement
  double seconds_refine = 0, seconds_charge = 0, seconds_trace = 0;
  double seconds_seed_weld = 0;  // of seconds_trace: the seeds' welds
  bool charges_cached = false, lines_cached = false;
  std::vector<std::string> warnings;
  // The seeds' edge weld (geometry::weld_by_edges at
  // seed_edge_weld_tolerance, consistent winding) when the lines were traced
  // here, so that the UV stage's weld of the same recipe is not computed
  // again (4 s of a 124k scan's map); empty when the lines came from the cache.
  std::optional<geometry::Weld> seed_edge_weld;
};

FieldBranchResult run_field_branch(const Soup& soup, const std::string& soup_hash,
                                   const FieldBranchOptions& options, cache::Store* cache,
                                   Progress& progress);

}  // namespace soupuv::pipeline
