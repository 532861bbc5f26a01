#include "soupuv/uvsolve/soup_uv_solve.h"

#include <chrono>
#include <cmath>

#include "uvsolve/attach_islands.h"
#include "uvsolve/fold_cut.h"
#include "uvsolve/halve_island.h"
#include "uvsolve/island_solve.h"
#include "uvsolve/overlap_split.h"
#include "uvsolve/pack_islands.h"
#include "uvsolve/reembed.h"
#include "uvsolve/seam_merge.h"
#include "uvsolve/seam_smooth.h"
#include "uvsolve/seam_straighten.h"
#include "uvsolve/sliver_stack.h"
#include "uvsolve/union_merge.h"
#include "uvsolve/untangle.h"
#include "uvsolve/uv_mesh.h"

namespace soupuv::uvsolve {
namespace {
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// The progress reported after each step: the share of the UV solve's time
// spent up to there on the 124k scan of the corpus (uv_solve.*.seconds of
// its diagnostics), so that the bar moves about evenly. Each update is also
// where a canceled job stops: the longest step, the union merge, reports
// between its rounds as well.
constexpr double kAfterUvMesh = 0.03, kAfterFolds = 0.18, kAfterSolve = 0.22, kAfterOverlaps = 0.31,
                 kAfterUnions = 0.66, kAfterSeams = 0.80, kBeforePack = 0.85, kAfterFirstPack = 0.97;

nlohmann::json reembed_json(const detail::ReembedFigures& f) {
  return {{"islands", f.islands},
          {"pieces", f.pieces},
          {"singleton_pieces", f.singleton_pieces},
          {"split_topology", f.split_topology},
          {"split_flip", f.split_flip},
          {"split_stretch", f.split_stretch},
          {"lapping_pieces", f.lapping_pieces}};
}
}  // namespace

SoupUvResult solve_soup_uvs(const Soup& soup, const geometry::Weld& weld,
                            const std::vector<std::array<Vec2, 3>>& transferred,
                            const std::vector<int>& corner_chart, double uv_per_length,
                            double texel, const SoupUvOptions& options, Progress& progress) {
  SoupUvResult r;
  nlohmann::json& d = r.diagnostics;
  auto t0 = Clock::now();
  progress.update("uv_solve", 0);
  detail::UvLayout layout =
      detail::build_uv_mesh(soup, weld, transferred, corner_chart, texel, uv_per_length);
  const std::vector<geometry::AdjacentPair> pairs = geometry::edge_adjacency(weld, soup.triangles.size());
  // A step's diagnostics: its own figures, then what every step reports
  // (the islands and the weld's pairs it leaves, its seconds since `start`).
  auto report = [&](const char* name, nlohmann::json figures, Clock::time_point start) {
    figures["islands"] = layout.island_count;
    figures["kept_pairs"] = detail::kept_pair_share(pairs, layout);
    figures["seconds"] = since(start);
    d[name] = std::move(figures);
  };
  report("uv_mesh", {{"vertices", layout.uv.size()}}, t0);
  progress.update("uv_solve", kAfterUvMesh);

  auto t_untangle = Clock::now();
  const size_t mirrored = detail::orient_islands(soup, layout);
  const detail::UntangleFigures uf = detail::untangle_islands(
      soup, uv_per_length, options.collapse_ratio, options.untangle_iterations, options.threads, layout);
  d["untangle"] = {{"mirrored_islands", mirrored},
                   {"folded_islands", uf.folded_islands},
                   {"untangled_islands", uf.untangled_islands},
                   {"folded_before", uf.bad_before},
                   {"folded_after", uf.bad_after},
                   {"seconds", since(t_untangle)}};

  // The overlap samples: finer than the final texels. The packed scale is
  // not known yet; the square's side over the islands' total area at full
  // use bounds it from above, so these samples are at least that fine.
  double rest_area = 0;
  for (size_t t = 0; t < soup.triangles.size(); ++t) rest_area += triangle_area(soup, t);
  rest_area *= uv_per_length * uv_per_length;
  const double cell =
      (rest_area > 0 ? std::sqrt(rest_area) / options.texture_size : 1.0) / options.overlap_samples_per_texel;

  // The selected islands flattened again from their own shape; its figures
  // under `name`.
  auto reembed = [&](const std::vector<uint8_t>& selected, const char* name, Clock::time_point t0) {
    const detail::ReembedFigures rf = detail::reembed_islands(
        soup, uv_per_length, selected, cell, options.reembed_max_stretch, options.solve_iterations, options.threads, layout);
    nlohmann::json j = reembed_json(rf);
    j["kept_pairs"] = detail::kept_pair_share(pairs, layout);
    j["seconds"] = since(t0);
    d[name] = j;
  };

  // Islands still folded are flattened again from their own shape.
  if (options.reembed) {
    auto t_re = Clock::now();
    std::vector<uint8_t> folded(layout.island_count, 0);
    for (size_t t = 0; t < layout.corner_vertex.size(); ++t)
      if (detail::is_folded(soup, uv_per_length, options.collapse_ratio, layout, t)) folded[layout.island[t]] = 1;
    reembed(folded, "reembed_folds", t_re);
  }
  progress.update("uv_solve", kAfterFolds);

  auto t1 = Clock::now();
  const detail::FoldCutFigures fc = detail::cut_folds(soup, uv_per_length, options.collapse_ratio, layout);
  report("fold_cut",
         {{"cut_triangles", fc.cut_triangles},
          {"unfolded_triangles", fc.unfolded_triangles},
          {"seeded_islands", fc.seeded_islands}},
         t1);

  auto t2 = Clock::now();
  const detail::SolveFigures sf =
      detail::solve_islands(soup, uv_per_length, options.solve_iterations, options.threads, layout);
  d["solve"] = {{"solved_islands", sf.solved_islands},
                {"unstarted_islands", sf.unstarted_islands},
                {"energy_before", sf.energy_before},
                {"energy_after", sf.energy_after},
                {"max_iterations_used", sf.max_iterations_used},
                {"seconds", since(t2)}};
  progress.update("uv_solve", kAfterSolve);

  // Islands whose image laps over itself are flattened again from their
  // own shape; the split below cuts what still laps.
  auto t3 = Clock::now();
  if (options.reembed) {
    const auto islands = detail::island_triangles(layout);
    std::vector<uint8_t> lapping(islands.size(), 0);
#pragma omp parallel for schedule(dynamic, 1) num_threads(std::max(1, options.threads))
    for (size_t i = 0; i < islands.size(); ++i) {
      if (islands[i].size() < 2) continue;
      double a = 0;
      for (uint32_t t : islands[i]) a += 0.5 * std::abs(detail::signed_area2(layout, t));
      lapping[i] = double(detail::overlap_samples(layout, islands[i], cell)) > detail::kLapShare * a / (cell * cell);
    }
    reembed(lapping, "reembed_overlaps", t3);
  }
  const detail::OverlapSplitFigures of = detail::split_overlaps(cell, options.threads, layout);
  report("overlap_split",
         {{"overlapping_islands", of.overlapping_islands},
          {"pieces_added", of.pieces_added},
          {"singleton_pieces", of.singleton_pieces},
          {"unfolded_singletons", of.unfolded_singletons}},
         t3);
  progress.update("uv_solve", kAfterOverlaps);

  if (options.reembed && options.straighten_seams) {
    auto t_st = Clock::now();
    const detail::SeamStraightenFigures sf2 =
        detail::straighten_seams(soup, uv_per_length, pairs, cell, options.reembed_max_stretch,
                                 options.solve_iterations, options.threads, layout);
    report("seam_straighten",
           {{"seams", sf2.seams},
            {"shorter", sf2.shorter},
            {"straightened", sf2.straightened},
            {"pairs_gained", sf2.pairs_gained},
            {"refused", sf2.refused},
            {"over_budget", sf2.over_budget}},
           t_st);
  }
  // Islands whose shapes flatten together are joined by flattening the union.
  if (options.reembed) {
    auto t_um = Clock::now();
    const detail::UnionMergeFigures uf2 = detail::merge_by_reflattening(
        soup, uv_per_length, pairs, cell, options.reembed_max_stretch,
        options.solve_iterations, options.merge_attempts_per_island, options.slit_unions, options.threads, layout,
        [&](double share) { progress.update("uv_solve", kAfterOverlaps + share * (kAfterUnions - kAfterOverlaps)); });
    report("union_merge",
           {{"attempts", uf2.attempts},
            {"joined", uf2.joined},
            {"repeated", uf2.repeated},
            {"forecast_refused", uf2.forecast_refused},
            {"joined_locally", uf2.joined_locally},
            {"slit", uf2.slit}},
           t_um);
  }
  progress.update("uv_solve", kAfterUnions);

  // Seams the transfer or the split cut where a flat map can close them
  // are joined, then the joined islands solved and checked again.
  auto t_merge = Clock::now();
  const detail::SeamMergeFigures mf = detail::merge_seams(
      soup, pairs, cell, uv_per_length, options.collapse_ratio, options.reembed_max_stretch,
      options.merge_attempts_per_island * size_t(layout.island_count), options.merge_relax_max_triangles,
      layout);
  nlohmann::json merge = {{"attempts", mf.attempts},
                          {"joined", mf.joined},
                          {"refused_fold", mf.refused_fold},
                          {"refused_overlap", mf.refused_overlap},
                          {"refused_stretch", mf.refused_stretch},
                          {"islands", layout.island_count},
                          {"kept_pairs", detail::kept_pair_share(pairs, layout)}};
  if (mf.joined > 0) {
    const detail::SolveFigures again = detail::solve_islands(soup, uv_per_length, options.solve_iterations,
                                                             options.threads, layout, &mf.joined_island, cell);
    const detail::OverlapSplitFigures resplit = detail::split_overlaps(cell, options.threads, layout);
    merge["solve_energy_after"] = again.energy_after;
    merge["solve_kept_for_laps"] = again.kept_for_laps;
    merge["resplit_pieces"] = resplit.pieces_added;
    merge["kept_pairs_after_resplit"] = detail::kept_pair_share(pairs, layout);
  }
  merge["seconds"] = since(t_merge);
  d["seam_merge"] = merge;
  progress.update("uv_solve", kAfterSeams);

  // Small islands attached to a neighbour: each island pays the packing
  // its padding p on every side, whatever its size. An island of side a
  // texels takes (a + p)^2 with it, more than twice its own a^2 when
  // a < p / (sqrt(2) - 1); its area is measured in the texels of a full
  // square (the finest the packing can reach), so no island is taken for
  // smaller than it will be.
  auto t_attach = Clock::now();
  const double full_texel = rest_area > 0 ? std::sqrt(rest_area) / options.texture_size : 0;
  const double small_side = options.padding_px / (std::sqrt(2.0) - 1) * full_texel;
  const detail::AttachFigures af = detail::attach_small_islands(
      soup, pairs, uv_per_length, options.collapse_ratio, options.reembed_max_stretch,
      options.attach_small_islands ? small_side * small_side : 0,
      options.attach_max_lap_texels * full_texel * full_texel, layout);
  report("attach",
         {{"candidates", af.candidates},
          {"attempts", af.attempts},
          {"attached", af.attached},
          {"refused_fold", af.refused_fold},
          {"refused_stretch", af.refused_stretch},
          {"refused_overlap", af.refused_overlap},
          {"attached_with_lap", af.attached_with_lap},
          {"lapped_texels", full_texel > 0 ? af.lapped_area / (full_texel * full_texel) : 0.0}},
         t_attach);

  // Triangles that zigzag across a seam join the island they are welded
  // to on two or three edges.
  if (options.smooth_seams) {
    auto t_smooth = Clock::now();
    const detail::SeamSmoothFigures sm = detail::smooth_seams(
        soup, pairs, uv_per_length, options.collapse_ratio, options.reembed_max_stretch,
        options.attach_max_lap_texels * full_texel * full_texel, layout);
    report("seam_smooth",
           {{"candidates", sm.candidates},
            {"moved", sm.moved},
            {"relaxed", sm.relaxed},
            {"refused_fold", sm.refused_fold},
            {"refused_stretch", sm.refused_stretch},
            {"refused_overlap", sm.refused_overlap},
            {"passes", sm.passes}},
           t_smooth);
  }

  // Stacks of slivers the noise scrambles: one grid each, ranked by height.
  if (options.sliver_stacks) {
    auto t_stack = Clock::now();
    const detail::SliverStackFigures sf = detail::lay_sliver_stacks(soup, pairs, uv_per_length, layout);
    report("sliver_stacks",
           {{"noise", sf.noise},
            {"stacks", sf.stacks},
            {"columns", sf.columns},
            {"triangles", sf.triangles},
            {"skipped_stacks", sf.skipped_stacks},
            {"kept_by_islands", sf.kept_by_islands}},
           t_stack);
  }

  progress.update("uv_solve", kBeforePack);
  auto t4 = Clock::now();
  detail::PackFigures pf = detail::pack_islands(layout, options.texture_size, options.padding_px,
                                                options.threads, r.corner_uvs);
  // Few large islands fill the square badly: halved and packed again where
  // that gains (halve_island.h).
  nlohmann::json halving = nlohmann::json::array();
  for (const detail::HalvingRound& h :
       detail::halve_to_pack(pairs, options.halving, options.utilisation_target, options.texture_size,
                             options.padding_px, options.threads, layout, r.corner_uvs, pf)) {
    nlohmann::json j = {{"halved", h.halved}, {"kept_pairs", h.kept_pairs}};
    if (h.packed) j["utilisation"] = h.utilisation, j["kept"] = h.kept;
    halving.push_back(j);
  }
  progress.update("uv_solve", kAfterFirstPack);
  // Still below the utilisation target: packed again the thorough way,
  // kept where denser (it costs seconds, so only here).
  nlohmann::json thorough;
  if (pf.utilisation < options.utilisation_target && pf.units <= detail::kThoroughMaxUnits) {
    std::vector<std::array<Vec2, 3>> uvs;
    const detail::PackFigures tried = detail::pack_islands(layout, options.texture_size, options.padding_px,
                                                           options.threads, uvs, detail::PackEffort::thorough);
    thorough = {{"utilisation", tried.utilisation}, {"kept", tried.utilisation > pf.utilisation}};
    if (tried.utilisation > pf.utilisation) pf = tried, r.corner_uvs = std::move(uvs);
  }
  report("pack",
         {{"texels_per_uv", pf.texels_per_uv},
          {"utilisation", pf.utilisation},
          {"attempts", pf.attempts},
          {"units", pf.units},
          {"grouped_islands", pf.grouped_islands},
          {"halving", halving},
          {"thorough", thorough}},
         t4);
  d["seconds"] = since(t0);
  progress.update("uv_solve", 1);
  return r;
}

}  // namespace soupuv::uvsolve
