// The UV half of run_map, where the two branches meet: the field lines land
// on the proxy (transfer, §8 chart fix), then the soup UV solve
// (uvsolve/soup_uv_solve.h) turns the landing into the final map.
//
//   run_uv_stage(soup, field, branch, options, welds, threads, progress)
//     soup, field  the soup and its field branch's lines (line_of_corner)
//     branch       the proxy and its atlas
//     options      MapOptions (transfer and UV solve options)
//     welds        the soup's edge weld and its neighbour pairs
//   -> per-triangle corner UVs, the transfer's counts, the UV solve's
//      diagnostics and the seconds.
#pragma once

#include <array>
#include <vector>

#include <nlohmann/json.hpp>

#include "pipeline/field_branch.h"
#include "pipeline/proxy_branch.h"
#include "soupuv/pipeline.h"
#include "soupuv/geometry/weld.h"

namespace soupuv::pipeline {

struct UvStageWelds {
  const geometry::Weld* weld = nullptr;  // edge weld (§8 neighbours, UV solve)
  const std::vector<geometry::AdjacentPair>* neighbours = nullptr;  // null: §8 per triangle
};

struct UvStage {
  transfer::TransferResult tr;  // tr.corner_uvs: the final UVs
  nlohmann::json solve;         // MapResult's "uv_solve"
  double seconds_transfer = 0, seconds_solve = 0;
};

UvStage run_uv_stage(const Soup& soup, const FieldBranchResult& field, const ProxyBranch& branch,
                     const MapOptions& options, const UvStageWelds& welds, int threads,
                     Progress& progress);

}  // namespace soupuv::pipeline
