#include "pipeline/uv_stage.h"

#include <chrono>

namespace soupuv::pipeline {

namespace {
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }
void solve_stage(const Soup& soup, const atlas::Atlas& atlas, const MapOptions& options,
                 const UvStageWelds& welds, int threads, UvStage& s, Progress& progress);
}  // namespace

UvStage run_uv_stage(const Soup& soup, const FieldBranchResult& field, const ProxyBranch& branch,
                     const MapOptions& options, const UvStageWelds& welds, int threads,
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
  s.seconds_transfer = since(t_transfer);
  solve_stage(soup, atlas, options, welds, threads, s, progress);
  return s;
}

namespace {

// The soup UV solve (uvsolve/soup_uv_solve.h) on the transferred map.
void solve_stage(const Soup& soup, const atlas::Atlas& atlas, const MapOptions& options,
                 const UvStageWelds& welds, int threads, UvStage& s, Progress& progress) {
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
