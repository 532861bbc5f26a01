// The UV half of run_map, where the two branches meet: the field lines land
// on the proxy (transfer, §8 chart fix, cut-triangle probes), then the local
// UV repair, its strict retry, the re-weld and the island relaxation
// (MapOptions says which run).
// run_map calls it once per (proxy, atlas) candidate against the one field.
//
//   run_uv_stage(soup, field, branch, options, welds, threads, progress)
//     soup, field  the soup and its field branch's lines (line_of_corner)
//     branch       the candidate's proxy and atlas
//     options      MapOptions (transfer, repair, reweld switches)
//     welds        the soup's edge weld and its neighbour pairs, and the
//                  metric adjacency for the "before repair" figures
//   -> per-triangle corner UVs, the transfer's counts, the unrepaired UVs
//      (when the repair ran), the repair's and the island relaxation's
//      diagnostics and the seconds.
#pragma once

#include <array>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pipeline/field_branch.h"
#include "pipeline/proxy_branch.h"
#include "soupuv/pipeline.h"
#include "soupuv/quality/weld.h"

namespace soupuv::pipeline {

struct UvStageWelds {
  const quality::Weld* weld = nullptr;  // edge weld (§8 neighbours, repair)
  const std::vector<quality::AdjacentPair>* neighbours = nullptr;  // null: §8 per triangle
  const std::vector<quality::AdjacentPair>* adjacency = nullptr;   // metric pairs
  // The strict retry's weld comes from this cache (pipeline/weld_cache.h)
  // and, once built, is kept here for the next candidate.
  cache::Store* cache = nullptr;
  std::string soup_hash;
  std::shared_ptr<quality::Weld> strict;
  // The island relaxation's weld (the soup's corners by distance, as the
  // candidate choice welds), built on first use and kept for the next.
  std::shared_ptr<quality::Weld> corners;
};

struct UvStage {
  transfer::TransferResult tr;  // tr.corner_uvs: the final UVs
  size_t cut_corrected = 0;
  std::vector<std::array<Vec2, 3>> unrepaired;  // empty when the repair is off
  nlohmann::json repair;                        // MapResult's "uv_repair"
  nlohmann::json island;                        // MapResult's "island_relax"
  nlohmann::json solve;                         // MapResult's "uv_solve"
  double seconds_transfer = 0, seconds_repair = 0, seconds_island = 0, seconds_solve = 0;
};

UvStage run_uv_stage(const Soup& soup, const FieldBranchResult& field, const ProxyBranch& branch,
                     const MapOptions& options, UvStageWelds& welds, int threads,
                     Progress& progress);

}  // namespace soupuv::pipeline
