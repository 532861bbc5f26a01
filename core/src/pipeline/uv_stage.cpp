#include "pipeline/uv_stage.h"

#include <chrono>

#include "pipeline/weld_cache.h"
#include "soupuv/quality/uv_metrics.h"
#include "soupuv/transfer/intersect.h"
#include "soupuv/transfer/uv_reweld.h"

namespace soupuv::pipeline {

namespace {
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }
void repair_stage(const Soup& soup, const FieldBranchResult& field, const atlas::Atlas& atlas,
                  const MapOptions& options, UvStageWelds& welds, UvStage& s, Progress& progress);
void relax_stage(const Soup& soup, const atlas::Atlas& atlas, const MapOptions& options,
                 UvStageWelds& welds, int threads, UvStage& s, Progress& progress);
void solve_stage(const Soup& soup, const atlas::Atlas& atlas, const MapOptions& options,
                 UvStageWelds& welds, int threads, UvStage& s, Progress& progress);
}  // namespace

UvStage run_uv_stage(const Soup& soup, const FieldBranchResult& field, const ProxyBranch& branch,
                     const MapOptions& options, UvStageWelds& welds, int threads,
                     Progress& progress) {
  const proxy::ProxyResult& px = branch.proxy;
  const atlas::Atlas& atlas = branch.atlas.atlas;
  UvStage s;
  transfer::TransferOptions to = options.transfer;
  to.threads = threads;
  to.neighbours = welds.neighbours;
  auto t_transfer = Clock::now();
  s.tr = field.line_of_corner.empty()
             ? transfer::transfer_uvs(soup, field.lines, px.proxy, atlas, to, progress)
             : transfer::transfer_uvs(soup, field.lines, field.line_of_corner, px.proxy, atlas, to,
                                      progress);
  transfer::TransferResult& tr = s.tr;
  if (!field.probes.empty()) {
    std::vector<Vec3> starts;
    for (const auto& p : field.probes) starts.insert(starts.end(), p.points.begin(), p.points.end());
    std::vector<Vec3> ordered(field.probe_lines.size());
    for (size_t i = 0; i < field.probe_lines.size(); ++i) ordered[i] = starts[field.probe_lines.corner[i]];
    auto landing = transfer::land_lines(field.probe_lines, ordered, px.proxy);
    std::vector<Vec2> probe_uvs(starts.size(), Vec2{0, 0});
    for (size_t i = 0; i < landing.size(); ++i)
      probe_uvs[field.probe_lines.corner[i]] = transfer::atlas_uv(atlas, landing[i]);
    s.cut_corrected = transfer::apply_cut_probes(soup, field.probes, probe_uvs, tr.corner_uvs);
  }
  s.seconds_transfer = since(t_transfer);
  if (options.soup_uv_solve) {
    s.repair = {{"enabled", false}};
    s.island = {{"enabled", false}, {"ran", false}};
    solve_stage(soup, atlas, options, welds, threads, s, progress);
    return s;
  }
  s.repair = {{"enabled", options.uv_repair}};
  if (options.uv_repair) repair_stage(soup, field, atlas, options, welds, s, progress);
  relax_stage(soup, atlas, options, welds, threads, s, progress);
  return s;
}

namespace {

// The repair, with the figures of the unrepaired map beside it so every
// run shows what the post-process changed.
void repair_stage(const Soup& soup, const FieldBranchResult& field, const atlas::Atlas& atlas,
                  const MapOptions& options, UvStageWelds& welds, UvStage& s, Progress& progress) {
  const double diag = bounding_box(soup).diagonal();
  transfer::TransferResult& tr = s.tr;
  s.unrepaired = tr.corner_uvs;
  quality::UvMetricsOptions mo;
  mo.texture_size = options.metrics_texture_size;
  mo.uv_per_length = atlas.uv_per_length;
  const quality::UvMetrics before = quality::uv_metrics(soup, tr.corner_uvs, *welds.adjacency, mo);
  // A triangle's chart: the one two of its corners landed on (else corner
  // 0's); the repair moves a corner on another chart onto it.
  std::vector<int> corner_chart(tr.landing.size()), chart(soup.triangles.size());
  for (size_t c = 0; c < corner_chart.size(); ++c) corner_chart[c] = atlas.face_chart[tr.landing[c].face];
  for (size_t t = 0; t < chart.size(); ++t) {
    const int* k = &corner_chart[3 * t];
    chart[t] = k[1] == k[2] ? k[1] : k[0];
  }
  transfer::UvRepairOptions ro = options.repair;
  if (options.repair_split_triangles) ro.corner_chart = &corner_chart;
  // The copies that share a line share a UV: the repair must move them
  // together, or it cuts the pairs the shared lines made continuous.
  quality::Weld line_weld;
  if (field.line_of_corner.size() == 3 * soup.triangles.size()) {
    line_weld.corner_vertex = field.line_of_corner;
    line_weld.vertex_count = uint32_t(field.lines.size());
  }
  const quality::Weld& weld = *welds.weld;
  const quality::Weld& repair_weld =
      options.repair_weld_lines && !line_weld.corner_vertex.empty() ? line_weld : weld;
  transfer::UvRepairResult rep = transfer::repair_uvs(soup, repair_weld, chart, atlas.uv_per_length,
                                                      tr.corner_uvs, ro, progress);
  s.seconds_repair = rep.seconds;
  s.repair.update(rep.diagnostics());
  // Patches that failed mostly sit where the weld joined distinct vertices
  // (rows of the soup closer than its noise). Retry the triangles still bad
  // on a stricter weld that leaves ambiguous edges unmatched: a sparser but
  // mostly right surface the repair can lay flat.
  if (rep.failed_patches > 0 && options.weld_by_edges && options.repair_strict_retry > 1) {
    if (!welds.strict) {
      bool hit = false;
      welds.strict = std::make_shared<quality::Weld>(cached_weld(
          welds.cache, welds.soup_hash,
          weld_recipe("edges", {options.edge_weld_tolerance * diag, options.repair_strict_retry}),
          [&] { return quality::weld_by_edges(soup, options.edge_weld_tolerance * diag, options.repair_strict_retry); },
          hit));
    }
    const quality::Weld& strict = *welds.strict;
    transfer::UvRepairOptions retry = ro;
    retry.only_triangles = &rep.failed_triangles;  // elsewhere the first pass did its best
    transfer::UvRepairResult again = transfer::repair_uvs(soup, strict, chart, atlas.uv_per_length,
                                                          tr.corner_uvs, retry, progress);
    s.seconds_repair += again.seconds;
    s.repair["strict_retry"] = again.diagnostics();
  }
  // Copies the repair left apart on one chart go back to one UV where that
  // folds nothing (transfer/uv_reweld.h).
  if (options.uv_reweld) {
    const transfer::UvReweldResult rw =
        transfer::reweld_uvs(soup, line_weld.corner_vertex.empty() ? weld : line_weld, chart,
                             atlas.uv_per_length, tr.corner_uvs, options.reweld);
    s.seconds_repair += rw.seconds;
    s.repair["reweld"] = rw.diagnostics();
  }
  s.repair["before"] = {{"flipped_fraction", before.flipped_fraction},
                        {"stretch_l2", before.stretch_l2},
                        {"stretch_median", before.stretch_median},
                        {"continuity", before.continuity},
                        {"continuity_1texel", before.continuity_1texel},
                        {"islands", before.islands}};
  s.repair["options"] = {{"stretch_threshold", options.repair.stretch_threshold},
                         {"expansion_threshold", options.repair.expansion_threshold},
                         {"max_growth", options.repair.max_growth}};
}

// The island relaxation (transfer/island_relax.h) on the soup's corner weld.
void relax_stage(const Soup& soup, const atlas::Atlas& atlas, const MapOptions& options,
                 UvStageWelds& welds, int threads, UvStage& s, Progress& progress) {
  const bool runs = options.island_relax && (options.island_relax_max_triangles == 0 ||
                                             soup.triangles.size() <= options.island_relax_max_triangles);
  s.island = {{"enabled", options.island_relax}, {"ran", runs}};
  if (!runs) return;
  auto t0 = Clock::now();
  if (!welds.corners) {
    const double diag = bounding_box(soup).diagonal();
    bool hit = false;
    welds.corners = std::make_shared<quality::Weld>(cached_weld(
        welds.cache, welds.soup_hash,
        weld_recipe("corners", {options.weld_tolerance * diag, options.weld_edge_fraction}),
        [&] { return quality::weld_corners(soup, options.weld_tolerance * diag, options.weld_edge_fraction); },
        hit));
  }
  transfer::IslandRelaxOptions io = options.island;
  io.texture_size = options.metrics_texture_size;
  io.uv_per_length = atlas.uv_per_length;
  io.threads = threads;
  io.also_weld = welds.weld;
  const transfer::IslandRelaxResult r =
      transfer::relax_islands(soup, *welds.corners, s.tr.corner_uvs, io, progress);
  s.island.update(r.diagnostics());
  s.seconds_island = since(t0);
  s.island["seconds"] = s.seconds_island;
}

// The soup UV solve (uvsolve/soup_uv_solve.h) on the transferred map.
void solve_stage(const Soup& soup, const atlas::Atlas& atlas, const MapOptions& options,
                 UvStageWelds& welds, int threads, UvStage& s, Progress& progress) {
  auto t0 = Clock::now();
  std::vector<int> corner_chart(s.tr.landing.size());
  for (size_t c = 0; c < corner_chart.size(); ++c) corner_chart[c] = atlas.face_chart[s.tr.landing[c].face];
  uvsolve::SoupUvOptions o = options.uv_solve;
  o.threads = threads;
  uvsolve::SoupUvResult r = uvsolve::solve_soup_uvs(soup, *welds.weld, s.tr.corner_uvs, corner_chart,
                                                    atlas.uv_per_length, 1.0 / options.metrics_texture_size,
                                                    o, progress);
  s.tr.corner_uvs = std::move(r.corner_uvs);
  s.solve = std::move(r.diagnostics);
  s.seconds_solve = since(t0);
}

}  // namespace

}  // namespace soupuv::pipeline
