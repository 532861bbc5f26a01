// The field branch of run_map: [intersection refinement] -> charge -> trace
// with one traced side per welded component, cached by content.
//
// Input : the soup, its geometry hash, options, an optional cache.
// Output: one field line per soup corner (only original corners are traced,
//         whatever the refinement added) and the branch's diagnostics.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "soupuv/cache/store.h"
#include "soupuv/field/field.h"
#include "soupuv/progress.h"
#include "soupuv/soup.h"
#include "soupuv/transfer/intersect.h"

namespace soupuv::pipeline {

struct FieldBranchOptions {
  field::ChargeOptions charge;
  field::TraceOptions trace;
  bool refine_intersections = true;
  bool trace_cut_probes = false;   // probes of cut triangles (intersect.h)
  bool orient_sides = true;
  // Copies of one welded position share one field line (shared_seeds.h);
  // false: one line per corner from its own triangle (the paper's seeding).
  bool share_lines = true;
  double weld_tolerance = 0;       // absolute
  double weld_edge_fraction = 0.3;
  int threads = 1;
};

struct FieldBranchResult {
  field::FieldLines lines;
  // With shared lines: the line of every soup corner (lines.corner names one
  // corner per line). Empty: line i belongs to corner lines.corner[i] alone.
  std::vector<uint32_t> line_of_corner;
  // Cut triangles (§12.1): probe points and their lines (line i: probe i/3,
  // point i%3), for transfer::apply_cut_probes.
  std::vector<transfer::CutProbe> probes;
  field::FieldLines probe_lines;
  nlohmann::json charge;        // charge diagnostics (solver, history, ...)
  nlohmann::json trace;         // trace diagnostics (ends, steps, ...)
  nlohmann::json orient;        // side choice
  nlohmann::json intersections; // refinement
  double seconds_refine = 0, seconds_charge = 0, seconds_trace = 0;
  bool charges_cached = false, lines_cached = false;
  std::vector<std::string> warnings;
};

FieldBranchResult run_field_branch(const Soup& soup, const std::string& soup_hash,
                                   const FieldBranchOptions& options, cache::Store* cache,
                                   Progress& progress);

}  // namespace soupuv::pipeline
