#include "soupuv/pipeline.h"

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <exception>
#include <future>
#include <thread>

#include "pipeline/field_branch.h"
#include "pipeline/proxy_branch.h"
#include "pipeline/uv_stage.h"
#include "pipeline/weld_cache.h"
#include "soupuv/baseline/box_projection.h"
#include "soupuv/cache/store.h"
#include "soupuv/errors.h"
#include "soupuv/quality/continuity_bound.h"
#include "soupuv/quality/discontinuity.h"
#include "soupuv/quality/stretch_tail.h"
#include "soupuv/quality/uv_metrics.h"

namespace soupuv {

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// A Progress for one branch: forwards to the caller's (which may throw
// canceled) and has its own cancel token, so a failing branch can stop its
// sibling without touching the caller's token.
Progress child_of(Progress& parent) {
  return Progress([&parent](std::string_view stage, double f) { parent.update(stage, f); });
}

// The metric's weld: the original's own vertices, else the soup's corners
// welded by position.
geometry::Weld metric_weld(const Soup& soup, const MapOptions& options) {
  if (options.original) return geometry::weld_corners(*options.original, 0.0);
  const double diag = bounding_box(soup).diagonal();
  return geometry::weld_corners(soup, options.weld_tolerance * diag, options.weld_edge_fraction);
}

// The metric's weld and its neighbour pairs, computed once per map (the
// weld alone took 5 s of a 124k scan's map, and it was computed twice).
struct MetricWeld {
  geometry::Weld weld;
  std::vector<geometry::AdjacentPair> pairs;
};

MetricWeld metric_weld_and_pairs(const Soup& soup, const MapOptions& options) {
  MetricWeld m;
  m.weld = metric_weld(soup, options);
  m.pairs = options.original ? quality::metric_adjacency(soup, options.original, 0)
                             : geometry::edge_adjacency(m.weld, soup.triangles.size());
  return m;
}

// uv.continuity_bound: what a low-distortion atlas can hardly beat (a cube:
// 11/18); an estimate (continuity_bound.h says where it is exceeded).
void add_continuity_bound(nlohmann::json& uv, const Soup& soup, const MapOptions& options,
                          const geometry::Weld& weld, const std::vector<geometry::AdjacentPair>& adjacency,
                          std::vector<std::string>& warnings) {
  const Soup& shape = options.original ? *options.original : soup;
  if (shape.triangles.size() != soup.triangles.size()) return;
  const quality::ContinuityBound b =
      quality::continuity_bound(shape, weld, adjacency);
  uv["continuity_bound"] = b.bound;
  uv["cone_vertices"] = b.cone_vertices;
  if (b.bound < 0.95)
    warnings.push_back("continuity is unlikely to exceed about " + std::to_string(b.bound) + ": " +
                       std::to_string(b.cone_vertices) + " cone vertices should lie on seams (uv.continuity_bound, an estimate)");
}

quality::UvMetrics measure(const Soup& soup, const std::vector<std::array<Vec2, 3>>& uvs,
                           const std::vector<geometry::AdjacentPair>& adjacency,
                           const MapOptions& options, double uv_per_length, double& seconds) {
  auto t0 = Clock::now();
  quality::UvMetricsOptions mo;
  mo.texture_size = options.metrics_texture_size;
  mo.uv_per_length = uv_per_length;
  auto m = quality::uv_metrics(soup, uvs, adjacency, mo);
  seconds = since(t0);
  return m;
}

nlohmann::json uv_json(const quality::UvMetrics& m, const Soup& soup, const MapOptions& options) {
  nlohmann::json j = quality::to_json(m);
  j["adjacency"] = options.original ? "original" : "weld";
  if (!options.original) j["weld_tolerance"] = options.weld_tolerance * bounding_box(soup).diagonal();
  return j;
}

nlohmann::json soup_json(const Soup& soup, const std::string& hash) {
  Box3 box = bounding_box(soup);
  return {{"triangles", soup.triangles.size()},
          {"positions", soup.positions.size()},
          {"geometry_hash", hash},
          {"bbox_diagonal", box.diagonal()}};
}

nlohmann::json cache_json(cache::Store* store, size_t hits, size_t misses) {
  nlohmann::json j = {{"enabled", store != nullptr}, {"hits", hits}, {"misses", misses}};
  if (store) {
    auto s = store->stats();
    j["store"] = {{"memory_hits", s.memory_hits}, {"disk_hits", s.disk_hits},
                  {"misses", s.misses},           {"entries", s.entries},
                  {"memory_bytes", s.memory_bytes}, {"directory", store->options().directory}};
  }
  return j;
}

// Per-triangle flags for the stretch tail's classes (quality/stretch_tail.h).
quality::TailFlags tail_flags(const Soup& soup, const geometry::Weld& weld,
                              const quality::CornerLanding& landed) {
  const size_t n = soup.triangles.size();
  quality::TailFlags f;
  if (weld.corner_vertex.size() == 3 * n) {
    // A welded vertex used on two charts lies on a seam or an open chart border.
    std::vector<int> chart_of(weld.vertex_count, -1);
    std::vector<uint8_t> border(weld.vertex_count, 0);
    for (size_t c = 0; c < 3 * n; ++c) {
      int& seen = chart_of[weld.corner_vertex[c]];
      if (seen >= 0 && seen != landed.final_chart[c]) border[weld.corner_vertex[c]] = 1;
      seen = landed.final_chart[c];
    }
    f.chart_border.assign(n, 0);
    for (size_t c = 0; c < 3 * n; ++c) f.chart_border[c / 3] |= border[weld.corner_vertex[c]];
  }
  return f;
}

MapResult run_box(const Soup& soup, const MapOptions& options, Progress& progress) {
  auto t0 = Clock::now();
  MapResult r;
  const std::string hash = geometry_hash(soup);
  baseline::BoxResult box = baseline::box_projection(soup, {}, progress);
  std::vector<std::array<Vec2, 3>> uvs(soup.triangles.size());
  for (size_t c = 0; c < box.corner_uvs.size(); ++c) uvs[c / 3][c % 3] = box.corner_uvs[c];
  double metric_seconds = 0;
  auto m = measure(soup, uvs, metric_weld_and_pairs(soup, options).pairs, options, 0, metric_seconds);
  r.corner_uvs = std::move(box.corner_uvs);
  nlohmann::json& d = r.diagnostics;
  d["method"] = "box";
  d["soup"] = soup_json(soup, hash);
  d["stages"] = {{"box", {{"seconds", box.seconds}}}, {"metrics", {{"seconds", metric_seconds}}}};
  d["box"] = {{"face_triangles", box.face_triangles}};
  d["uv"] = uv_json(m, soup, options);
  d["cache"] = cache_json(nullptr, 0, 0);
  d["warnings"] = soup.warnings;
  d["seconds"] = since(t0);
  return r;
}

}  // namespace

MapResult run_map(const io::Asset& asset, const MapOptions& options, Progress& progress) {
  MapResult r = run_map(asset.soup, options, progress);
  r.diagnostics["soup"]["dropped_degenerate"] = asset.dropped_degenerate;
  r.diagnostics["soup"]["skipped_primitives"] = asset.skipped_primitives;
  return r;
}

MapResult run_map(const Soup& soup, const MapOptions& options, Progress& progress) {
  if (soup.triangles.empty()) throw Error(ErrorCode::no_triangles, "the input has no triangles");
  if (options.method == MapMethod::box) return run_box(soup, options, progress);

  auto t0 = Clock::now();
  const std::string hash = geometry_hash(soup);
  const int total_threads = options.threads > 0 ? options.threads : omp_get_max_threads();
  // The field branch runs for minutes on large soups while proxy + atlas take
  // seconds: splitting the cores evenly left half of them idle once the proxy
  // was done (100k-triangle torus: 230 s wall at 236 s CPU on 2 cores). So the
  // field branch takes every thread and the proxy branch half of them; their
  // short overlap oversubscribes by that half.
  const int field_threads = total_threads;
  const int proxy_threads = std::max(1, total_threads / 2);
  const double diag = bounding_box(soup).diagonal();

  pipeline::FieldBranchOptions fo;
  fo.charge = options.charge;
  fo.trace = options.trace;
  fo.refine_intersections = options.refine_intersections;
  fo.orient_sides = options.orient_sides;
  fo.share_lines = options.share_lines;
  fo.weld_tolerance = options.weld_tolerance * diag;
  fo.weld_edge_fraction = options.weld_edge_fraction;
  if (options.seed_weld_by_edges) fo.seed_edge_weld_tolerance = options.edge_weld_tolerance * diag;
  fo.seed_edge_fraction = options.seed_weld_edge_fraction;
  fo.threads = field_threads;
  fo.proxy_reach = pipeline::proxy_reach(soup, options.proxy);
  // The proxy mesh, handed from the proxy branch to the field branch's
  // trace (nullptr if the proxy branch failed: the field branch is then
  // canceled or its lines unused).
  std::promise<const TriMesh*> proxy_mesh;
  std::shared_future<const TriMesh*> proxy_mesh_ready = proxy_mesh.get_future().share();
  bool proxy_mesh_sent = false;
  if (options.stop_lines_at_proxy && !options.cache) fo.stop_surface = [proxy_mesh_ready] { return proxy_mesh_ready.get(); };

  // The two branches (paper Fig. 3): field on a second thread, proxy + atlas here.
  Progress field_progress = child_of(progress);
  Progress proxy_progress = child_of(progress);
  pipeline::FieldBranchResult field;
  std::exception_ptr field_error;
  double seconds_field_branch = 0;
  std::thread field_thread([&] {
    try {
      auto t_field = Clock::now();
      field = pipeline::run_field_branch(soup, hash, fo, options.cache, field_progress);
      seconds_field_branch = since(t_field);
    } catch (...) {
      field_error = std::current_exception();
      proxy_progress.cancel();
    }
  });
  pipeline::ProxyBranch pb;
  std::exception_ptr proxy_error;
  // The metric's weld needs only the soup: it is made here once the proxy
  // branch is done, while the field branch (the longer on every soup above
  // a few thousand triangles) still runs.
  MetricWeld metric;
  double seconds_metric_weld = 0;
  try {
    pipeline::run_proxy_branch(soup, options.proxy, options.atlas, options.relax_max_soup_per_proxy_face,
                               proxy_threads, proxy_progress, pb, [&](const TriMesh& mesh) {
                                 proxy_mesh.set_value(&mesh);
                                 proxy_mesh_sent = true;
                               });
    auto t_metric_weld = Clock::now();
    metric = metric_weld_and_pairs(soup, options);
    seconds_metric_weld = since(t_metric_weld);
  } catch (...) {
    proxy_error = std::current_exception();
    field_progress.cancel();
  }
  if (!proxy_mesh_sent) proxy_mesh.set_value(nullptr);  // never leave the field branch waiting
  field_thread.join();
  progress.check_canceled();  // the caller's cancel wins over a branch's own error
  // Report the root cause, not the sibling's "canceled".
  if (field_error && proxy_error) {
    try { std::rethrow_exception(field_error); }
    catch (const Error& e) { if (e.code() == ErrorCode::canceled) std::rethrow_exception(proxy_error); throw; }
  }
  if (field_error) std::rethrow_exception(field_error);
  if (proxy_error) std::rethrow_exception(proxy_error);

  // Transfer: the branches meet.
  auto t_weld = Clock::now();
  bool weld_cached = false;
  const geometry::Weld weld = pipeline::cached_weld(
      options.cache, hash,
      options.weld_by_edges
          ? pipeline::weld_recipe(std::string(geometry::kEdgeWeldAlgorithm) + "-consistent",
                                 {options.edge_weld_tolerance * diag, 1.0})
          : pipeline::weld_recipe("corners", {options.weld_tolerance * diag, options.weld_edge_fraction}),
      [&] {
        // The field branch's seeds used the same recipe: take theirs.
        if (options.weld_by_edges && field.seed_edge_weld && fo.seed_edge_weld_tolerance == options.edge_weld_tolerance * diag)
          return *field.seed_edge_weld;
        return options.weld_by_edges
                   ? geometry::weld_by_edges(soup, options.edge_weld_tolerance * diag, 1.0, false)
                   : geometry::weld_corners(soup, options.weld_tolerance * diag, options.weld_edge_fraction);
      },
      weld_cached);
  std::vector<geometry::AdjacentPair> neighbours;
  if (options.chart_fix_neighbours) neighbours = geometry::edge_adjacency(weld, soup.triangles.size());
  const auto& adjacency = metric.pairs;
  const double seconds_weld = since(t_weld);
  const pipeline::UvStageWelds welds{&weld, options.chart_fix_neighbours ? &neighbours : nullptr};
  pipeline::UvStage uv = pipeline::run_uv_stage(soup, field, pb, options, welds, total_threads, progress);

  transfer::TransferResult& tr = uv.tr;
  double metric_seconds = 0;
  // After the UV solve the map has its own density (0: derived from it, as
  // eval/uvmetrics.py derives it).
  quality::UvMetrics m = measure(soup, tr.corner_uvs, adjacency, options, 0.0, metric_seconds);
  auto t_report = Clock::now();
  quality::CornerLanding landed;
  landed.missed = tr.missed;
  landed.first_chart = tr.first_chart;
  landed.final_chart.resize(tr.landing.size());
  for (size_t c = 0; c < tr.landing.size(); ++c)
    landed.final_chart[c] = pb.atlas.atlas.face_chart[tr.landing[c].face];
  if (!field.line_of_corner.empty()) landed.line = field.line_of_corner;
  else {
    landed.line.assign(3 * soup.triangles.size(), UINT32_MAX);
    for (size_t l = 0; l < field.lines.size(); ++l)
      if (field.lines.corner[l] < landed.line.size()) landed.line[field.lines.corner[l]] = uint32_t(l);
  }
  const quality::DiscontinuityBreakdown causes = quality::discontinuity_breakdown(
      soup, tr.corner_uvs, adjacency, landed, options.metrics_texture_size, m.uv_per_length);
  const quality::StretchTail tail = quality::stretch_tail(
      soup, tr.corner_uvs, landed, tail_flags(soup, weld, landed));

  MapResult r;
  r.corner_uvs.reserve(3 * soup.triangles.size());
  for (const auto& t : tr.corner_uvs) r.corner_uvs.insert(r.corner_uvs.end(), t.begin(), t.end());

  nlohmann::json& d = r.diagnostics;
  d["method"] = "field";
  d["soup"] = soup_json(soup, hash);
  d["threads"] = {{"total", total_threads}, {"field", field_threads}, {"proxy", proxy_threads}};
  d["stages"] = {
      {"intersections", {{"seconds", field.seconds_refine}}},
      {"charge", {{"seconds", field.seconds_charge}, {"cached", field.charges_cached}}},
      {"trace", {{"seconds", field.seconds_trace}, {"cached", field.lines_cached}}},
      {"proxy", {{"seconds", pb.seconds_proxy}}},
      {"atlas", {{"seconds", pb.seconds_atlas}}},
      {"transfer", {{"seconds", uv.seconds_transfer}}},
      {"uv_solve", {{"seconds", uv.seconds_solve}}},
      {"metrics", {{"seconds", metric_seconds}}}};
  // The rest of the run, so the stages add up: the soup's welds for §8, the
  // UV solve and the metric; the field branch's cache look-up and decoding
  // when it computed nothing; the report's breakdowns below (filled in last).
  // The metric's weld ran beside the field branch: its seconds are not
  // part of the stage's.
  d["stages"]["weld"] = {{"seconds", seconds_weld}, {"cached", weld_cached},
                         {"metric_weld_seconds_beside_field_branch", seconds_metric_weld},
                         {"seed_weld_seconds_in_trace", field.seconds_seed_weld}};
  if (field.lines_cached) d["stages"]["field_cache"] = {{"seconds", seconds_field_branch}};
  d["proxy"] = pb.proxy.diagnostics();
  d["proxy"]["closed"] = pb.proxy.closed;
  d["proxy"]["manifold"] = pb.proxy.manifold;
  d["proxy"]["outer_components"] = pb.proxy.outer_components;
  d["atlas"] = pb.atlas.diagnostics();
  d["atlas"]["charts"] = pb.atlas.atlas.chart_count;
  d["atlas"]["uv_per_length"] = pb.atlas.atlas.uv_per_length;
  d["charge"] = field.charge;
  d["trace"] = field.trace;
  d["trace"]["lines"] = tr.lines;
  d["trace"]["hits"] = tr.hits;
  d["trace"]["hit_fraction"] = tr.hit_fraction();
  d["trace"]["fallback"] = tr.fallback_ray + tr.fallback_closest;
  d["trace"]["fallback_ray"] = tr.fallback_ray;
  d["trace"]["fallback_closest"] = tr.fallback_closest;
  d["trace"]["untraced_corners"] = tr.untraced_corners;
  d["orient"] = field.orient;
  d["intersections"] = field.intersections;
  d["transfer"] = {{"multi_chart_triangles", tr.multi_chart_triangles},
                   {"corrected_triangles", tr.corrected_triangles}};
  d["uv"] = uv_json(m, soup, options);
  d["uv"]["causes"] = causes.to_json();
  d["uv"]["stretch_tail"] = tail.to_json();
  d["uv_solve"] = uv.solve;
  size_t hits = size_t(field.charges_cached) + size_t(field.lines_cached);
  size_t misses = 2 - hits;
  d["cache"] = cache_json(options.cache, options.cache ? hits : 0, options.cache ? misses : 0);
  std::vector<std::string> warnings = soup.warnings;
  warnings.insert(warnings.end(), field.warnings.begin(), field.warnings.end());
  warnings.insert(warnings.end(), pb.proxy.warnings.begin(), pb.proxy.warnings.end());
  warnings.insert(warnings.end(), pb.atlas.stats.warnings.begin(), pb.atlas.stats.warnings.end());
  if (!pb.proxy.ok()) warnings.push_back("the proxy failed a check (see proxy.*)");
  add_continuity_bound(d["uv"], soup, options, metric.weld, adjacency, warnings);
  d["warnings"] = warnings;
  d["stages"]["report"] = {{"seconds", since(t_report)}};
  d["seconds"] = since(t0);

  if (options.keep_debug) {
    r.debug.proxy = std::move(pb.proxy.proxy);
    r.debug.atlas = std::move(pb.atlas.atlas);
    r.debug.lines = std::move(field.lines);
  }
  progress.update("done", 1);
  return r;
}

}  // namespace soupuv
