// build_atlas: the atlas stage's driver (see soupuv/atlas/build_atlas.h):
// seams -> segmentation -> per-chart disk check and flattening, splitting what
// fails -> merging, relaxation -> packing -> diagnostics; the steps between
// seams and packing once per segmentation budget tried (the cheapest seams
// are packed).
#include "soupuv/atlas/build_atlas.h"

#include <chrono>
#include <cmath>
#include <ctime>
#include <exception>

#include <omp.h>

#include "atlas/atlas_metrics.h"
#include "atlas/chart_mesh.h"
#include "atlas/flat_split.h"
#include "atlas/merge_charts.h"
#include "atlas/mesh_topology.h"
#include "atlas/pack.h"
#include "atlas/parameterize.h"
#include "atlas/raster_pack.h"
#include "atlas/relax_seams.h"
#include "atlas/seams.h"
#include "atlas/segment.h"
#include "atlas/split.h"
#include "soupuv/errors.h"

namespace soupuv::atlas {
namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

}  // namespace

nlohmann::json AtlasResult::diagnostics() const {
  const AtlasDiagnostics& s = stats;
  return {{"charts", s.charts},
          {"faces", s.faces},
          {"stretch_l2", s.stretch_l2},
          {"stretch_linf", s.stretch_linf},
          {"angle_distortion_deg", s.angle_distortion_deg},
          {"flipped", s.flipped},
          {"overlap", s.overlap},
          {"utilization", s.utilization},
          {"segment_rounds", s.segment_rounds},
          {"splits", s.splits},
          {"packing_splits", s.packing_splits},
          {"chart_merges", s.chart_merges},
          {"segment_angle_deg", s.segment_angle_deg},
          {"segment_budgets_tried", s.segment_budgets_tried},
          {"seam_edges", s.seam_edges},
          {"seam_length", s.seam_length},
          {"seam_length_relative", s.seam_length_relative},
          {"seam_cost_before_relax", s.seam_cost_before_relax},
          {"seam_cost", s.seam_cost},
          {"relaxed_pairs", s.relaxed_pairs},
          {"relaxed_faces", s.relaxed_faces},
          {"texture_size", atlas.texture_size},
          {"padding_px", atlas.padding_px},
          {"uv_per_length", atlas.uv_per_length},
          {"seconds", s.seconds},
          {"cpu_seconds", s.cpu_seconds},
          {"pack_attempts", s.pack_attempts},
          {"pack_method", s.pack_method},
          {"seconds_segment", s.seconds_segment},
          {"seconds_parameterize", s.seconds_parameterize},
          {"seconds_merge", s.seconds_merge},
          {"seconds_pack", s.seconds_pack},
          {"warnings", s.warnings}};
}

// The flattened charts of one segmentation budget, before packing.
struct Charted {
  AtlasResult result;              // stats so far
  std::vector<FlatChart> done;
  std::vector<int> face_chart;
  std::vector<int> face_local;
  int next_id = 0;
};

// Segmentation, flattening, merging and relaxation for one budget.
Charted chart_with_budget(const TriMesh& mesh, const MeshTopology& topology, const std::vector<char>& seam,
                          const AtlasOptions& options, double max_normal_deviation_deg, int threads,
                          Progress& progress) {
  const auto t0 = Clock::now();
  Charted charted;
  AtlasDiagnostics& stats = charted.result.stats;
  const int nf = static_cast<int>(mesh.faces.size());
  stats.faces = nf;
  stats.segment_angle_deg = max_normal_deviation_deg;
  Segmentation seg = segment_charts(topology, seam, max_normal_deviation_deg, progress);
  charted.face_chart = std::move(seg.face_chart);
  std::vector<int>& face_chart = charted.face_chart;
  stats.segment_rounds = seg.rounds;
  std::vector<std::vector<int>> pending(seg.count);
  for (int f = 0; f < nf; ++f) pending[face_chart[f]].push_back(f);
  int& next_id = charted.next_id;
  next_id = seg.count;
  stats.seconds_segment = since(t0);

  // Rounds: flatten every pending chart in parallel; the ones that fail are
  // split and come back in the next round. Halving sizes bound the rounds.
  const auto t1 = Clock::now();
  std::vector<FlatChart>& done = charted.done;
  std::vector<int>& face_local = charted.face_local;
  face_local.assign(nf, -1);
  int faces_done = 0;
  while (!pending.empty()) {
    const int n = static_cast<int>(pending.size());
    std::vector<FlatChart> flat(n);
    std::vector<char> ok(n, 0);
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (int i = 0; i < n; ++i) {
      flat[i].mesh = extract_chart(mesh, topology, pending[i], face_chart, seam, face_local);
      if (!flat[i].mesh.is_disk()) continue;
      ChartParameterization p =
          parameterize_chart(flat[i].mesh, options.arap_iterations, options.max_stretch);
      // A single face always flattens; nothing smaller exists to split into.
      if (p.ok || (pending[i].size() == 1 && !p.uv.empty())) {
        flat[i].uv = std::move(p.uv);
        ok[i] = 1;
      }
    }
    std::vector<std::vector<int>> next;
    for (int i = 0; i < n; ++i) {
      if (ok[i]) {
        faces_done += static_cast<int>(pending[i].size());
        done.push_back(std::move(flat[i]));
        continue;
      }
      if (pending[i].size() == 1)
        throw Error(ErrorCode::internal, "atlas: a single face could not be flattened");
      ++stats.splits;
      auto halves = split_chart(topology, seam, pending[i], face_chart);
      for (auto& h : halves) {
        if (h.empty()) continue;
        for (int f : h) face_chart[f] = next_id;
        ++next_id;
        next.push_back(std::move(h));
      }
    }
    pending = std::move(next);
    progress.update("atlas.parameterize", static_cast<double>(faces_done) / nf);
  }
  stats.seconds_parameterize = since(t1);

  const double merge_budget = options.merge_max_stretch > 0 ? options.merge_max_stretch : options.max_stretch;
  if (options.merge_charts) {
    const auto tm = Clock::now();
    progress.update("atlas.merge", 0);
    MergeOptions merge;
    merge.max_stretch = merge_budget;
    merge.stretch_sweeps = options.merge_stretch_sweeps;
    merge.arap_iterations = options.arap_iterations;
    merge.crease_deg = options.merge_crease_deg;
    merge.max_area_fraction = options.merge_max_area_fraction;
    merge.min_fill = options.merge_min_fill;
    merge.max_normal_deviation_deg = options.merge_max_normal_deviation_deg;
    merge.threads = threads;
    stats.chart_merges = merge_charts(mesh, topology, seam, done, face_chart, face_local, merge);
    stats.seconds_merge = since(tm);
  }
  stats.seam_cost_before_relax = weighted_seam_length(topology, face_chart, options.seam_weight);
  if (options.relax_seams) {
    progress.update("atlas.relax", 0);
    RelaxOptions relax;
    relax.max_stretch = options.merge_charts ? merge_budget : options.max_stretch;
    relax.arap_iterations = options.arap_iterations;
    relax.band_fraction = options.relax_band;
    relax.max_stretch_increase = options.relax_max_stretch_increase;
    relax.narrowings = options.relax_narrowings;
    relax.threads = threads;
    RelaxStats r = relax_seams(mesh, topology, seam, done, face_chart, face_local, options.seam_weight, relax);
    stats.relaxed_pairs = r.pairs_relaxed;
    stats.relaxed_faces = r.faces_moved;
  }
  stats.seam_cost = weighted_seam_length(topology, face_chart, options.seam_weight);
  return charted;
}

// Packing, the Atlas and its diagnostics.
AtlasResult pack_and_measure(const TriMesh& mesh, const MeshTopology& topology, const std::vector<char>& seam,
                             const AtlasOptions& options, Charted charted, int threads, Progress& progress) {
  AtlasResult result = std::move(charted.result);
  AtlasDiagnostics& stats = result.stats;
  const int nf = static_cast<int>(mesh.faces.size());
  std::vector<FlatChart>& done = charted.done;
  std::vector<int>& face_chart = charted.face_chart;
  std::vector<int>& face_local = charted.face_local;
  int& next_id = charted.next_id;
  // Packing rounds: while utilisation stays below the target, the largest
  // charts are halved (their UVs kept) and everything is packed again; the
  // best round wins.
  const auto t2 = Clock::now();
  std::vector<FlatChart> best_charts;
  PackResult packed;
  packed.utilization = -1;
  int splits_so_far = 0;
  for (int round = 0;; ++round) {
    progress.update("atlas.pack", round / (options.packing_split_rounds + 1.0));
    std::vector<FlatChart> trial = done;
    std::vector<PackChart> pack_input;
    for (FlatChart& c : trial) pack_input.push_back({&c.uv, &c.mesh.tri, &c.mesh.boundary});
    RasterPackOptions raster;
    raster.angles = options.pack_angles;
    raster.threads = threads;
    PackResult p = pack_charts(pack_input, options.texture_size, options.padding_px, raster);
    stats.pack_attempts += p.attempts;
    if (p.utilization > packed.utilization) {
      packed = p;
      stats.pack_method = p.method;
      best_charts = std::move(trial);
      stats.packing_splits = splits_so_far;
    }
    // Halving pays only while charts are few and big; among hundreds of
    // charts the packer already fills gaps with small ones. Merged charts
    // are never halved: merging traded utilisation for shorter seams, and
    // halving gave the seams back longer (suzanne's proxy in the pipeline:
    // 22 charts plain, 10 merged, 24 after 14 packing splits).
    if (p.utilization >= options.packing_split_below || round >= options.packing_split_rounds ||
        done.size() > 64 || options.merge_charts)
      break;
    std::vector<double> area(done.size(), 0);
    double largest = 0;
    for (size_t c = 0; c < done.size(); ++c) {
      for (const auto& t : done[c].mesh.tri)
        area[c] += 0.5 * std::fabs(cross(done[c].uv[t[1]] - done[c].uv[t[0]], done[c].uv[t[2]] - done[c].uv[t[0]]));
      largest = std::max(largest, area[c]);
    }
    std::vector<FlatChart> next;
    int split_now = 0;
    for (size_t c = 0; c < done.size(); ++c) {
      if (area[c] >= 0.5 * largest) {
        if (auto halves = split_flat_chart(done[c], mesh, topology, seam, face_chart, next_id, face_local)) {
          next.push_back(std::move(halves->first));
          next.push_back(std::move(halves->second));
          ++split_now;
          continue;
        }
      }
      next.push_back(std::move(done[c]));
    }
    done = std::move(next);
    splits_so_far += split_now;
    if (split_now == 0) break;
  }
  done = std::move(best_charts);
  stats.seconds_pack = since(t2);

  Atlas& atlas = result.atlas;
  atlas.face_uvs.resize(nf);
  atlas.face_chart.assign(nf, -1);
  atlas.chart_count = static_cast<int>(done.size());
  atlas.texture_size = options.texture_size;
  atlas.padding_px = options.padding_px;
  atlas.uv_per_length = packed.uv_per_length;
  for (int c = 0; c < atlas.chart_count; ++c) {
    const FlatChart& fc = done[c];
    for (size_t i = 0; i < fc.mesh.faces.size(); ++i) {
      int f = fc.mesh.faces[i];
      atlas.face_chart[f] = c;
      for (int k = 0; k < 3; ++k) atlas.face_uvs[f][k] = fc.uv[fc.mesh.tri[i][k]];
    }
  }

  progress.update("atlas.measure", 0);
  // Seams: the pipeline's continuity suffers wherever a field line crosses
  // one, so their length is reported next to the chart count.
  double surface = 0;
  for (double a : topology.face_area) surface += a;
  for (int f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k) {
      int g = topology.face_neighbor[f][k];
      if (f < g && atlas.face_chart[f] != atlas.face_chart[g])
        stats.seam_length += topology.edge_length[topology.face_edge[f][k]];
    }
  stats.seam_cost = weighted_seam_length(topology, atlas.face_chart, options.seam_weight);
  stats.seam_length_relative = surface > 0 ? stats.seam_length / std::sqrt(surface) : 0;
  AtlasMetrics m = measure_atlas(mesh, atlas);
  stats.charts = atlas.chart_count;
  stats.stretch_l2 = m.stretch_l2;
  stats.stretch_linf = m.stretch_linf;
  stats.angle_distortion_deg = m.angle_distortion_deg;
  stats.flipped = m.flipped;
  stats.overlap = m.overlap;
  stats.utilization = m.utilization;
  progress.update("atlas.measure", 1);
  return result;
}

AtlasResult build_atlas(const TriMesh& mesh, const AtlasOptions& options, Progress& progress) {
  const auto t0 = Clock::now();
  const std::clock_t cpu0 = std::clock();
  if (options.texture_size < 16 || options.texture_size > 65536)
    throw Error(ErrorCode::invalid_input, "atlas: texture_size must be in [16, 65536]");
  if (!(options.padding_px >= 0) || options.padding_px > options.texture_size / 4.0)
    throw Error(ErrorCode::invalid_input, "atlas: padding_px must be in [0, texture_size/4]");
  if (!(options.max_normal_deviation_deg > 0 && options.max_normal_deviation_deg < 90))
    throw Error(ErrorCode::invalid_input, "atlas: max_normal_deviation_deg must be in (0, 90)");
  if (!(options.merge_max_normal_deviation_deg >= 0 && options.merge_max_normal_deviation_deg <= 180))
    throw Error(ErrorCode::invalid_input, "atlas: merge_max_normal_deviation_deg must be in [0, 180]");
  if (!(options.max_stretch >= 1))
    throw Error(ErrorCode::invalid_input, "atlas: max_stretch must be at least 1");
  if (options.merge_stretch_sweeps < 0)
    throw Error(ErrorCode::invalid_input, "atlas: merge_stretch_sweeps must not be negative");
  if (!(options.merge_max_stretch == 0 || options.merge_max_stretch >= 1))
    throw Error(ErrorCode::invalid_input, "atlas: merge_max_stretch must be 0 or at least 1");
  if (!options.seam_weight.empty()) {
    if (options.seam_weight.size() != mesh.faces.size())
      throw Error(ErrorCode::invalid_input, "atlas: seam_weight needs one weight per face");
    for (double w : options.seam_weight)
      if (!(w > 0 && std::isfinite(w)))
        throw Error(ErrorCode::invalid_input, "atlas: seam weights must be positive and finite");
  }
  if (!(options.relax_band > 0))
    throw Error(ErrorCode::invalid_input, "atlas: relax_band must be positive");
  for (double a : options.alternative_normal_deviations_deg)
    if (!(a > 0 && a < 90))
      throw Error(ErrorCode::invalid_input, "atlas: alternative_normal_deviations_deg must be in (0, 90)");
  const int threads = options.threads > 0 ? options.threads : omp_get_max_threads();
  MeshTopology topology = build_topology(mesh);
  std::vector<char> seam(topology.edge_vertices.size(), 0);
  SeamPaths paths = trace_seam_hints(mesh, topology, options.seam_hints, options.alpha, options.beta);
  for (int e : paths.edges) seam[e] = 1;

  // Other budgets segment differently, and what merging and relaxation make
  // of a segmentation is hard to foresee; the weighted seam length predicts
  // the soup pairs the seams cut, so the cheapest charts win. Only with
  // weights: plain seam length says nothing about the soup. Chosen before
  // packing (most of the atlas's time), which with merged charts never
  // splits a chart, so the seams chosen are the seams packed.
  std::vector<double> budgets{options.max_normal_deviation_deg};
  if (!options.seam_weight.empty())
    budgets.insert(budgets.end(), options.alternative_normal_deviations_deg.begin(),
                   options.alternative_normal_deviations_deg.end());
  // The budgets are independent and run at least two at a time: the map's
  // proxy branch has one thread of two, and on small soups the field
  // branch is done long before the atlas (docs/tuning.md). Each budget's
  // own loops then run on its one thread; the pick is the same.
  std::vector<Charted> charted(budgets.size());
  std::vector<std::exception_ptr> failed(budgets.size());
  const int budget_threads = static_cast<int>(std::min<size_t>(budgets.size(), static_cast<size_t>(std::max(threads, 2))));
#pragma omp parallel for schedule(dynamic, 1) num_threads(budget_threads)
  for (size_t b = 0; b < budgets.size(); ++b) {
    try {
      charted[b] = chart_with_budget(mesh, topology, seam, options, budgets[b], budget_threads > 1 ? 1 : threads, progress);
    } catch (...) {
      failed[b] = std::current_exception();
    }
  }
  for (const auto& e : failed)
    if (e) std::rethrow_exception(e);
  Charted best = std::move(charted[0]);
  for (size_t b = 1; b < budgets.size(); ++b)
    if (charted[b].result.stats.seam_cost < best.result.stats.seam_cost) best = std::move(charted[b]);
  const int tried = static_cast<int>(budgets.size());
  AtlasResult result = pack_and_measure(mesh, topology, seam, options, std::move(best), threads, progress);
  AtlasDiagnostics& stats = result.stats;
  stats.segment_budgets_tried = tried;
  for (int e : paths.edges) result.forced_seams.push_back(topology.edge_vertices[e]);
  stats.seam_edges = static_cast<int>(paths.edges.size());
  stats.warnings.insert(stats.warnings.begin(), paths.warnings.begin(), paths.warnings.end());
  stats.seconds = since(t0);
  stats.cpu_seconds = static_cast<double>(std::clock() - cpu0) / CLOCKS_PER_SEC;
  return result;
}

}  // namespace soupuv::atlas
