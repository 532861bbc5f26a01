// soupuv-bench field-branch [--quick] [--triangles N] [--threads 1,2]
//                           [--variant NAME:key=value,...] [--map]
//
// The pipeline's trace alone, on the 100k noisy torus soup of
// `soupuv-bench pipeline --only torus-100k` (to_soup(torus_with(1, 0.5, N),
// 1e-3, 1)): intersections refined and charges solved once as run_map does,
// one shared seed per welded vertex (pipeline/shared_seeds.h), then
// trace_field_lines with the pipeline's TraceOptions (variant "pipeline") or
// a variant of them, once per thread count (the pipeline's stop: the box of
// field_branch.h for the default proxy ladder). Per run: TraceStats, evaluations
// per line, us per evaluation (wall and CPU), where the time goes along the
// lines (per step index: active lines, how many still take shortened
// near-surface steps; a least-squares split of the step times into a cost
// per near and per far evaluation), and what a stop at the bounding box
// grown by 1.25x the largest proxy offset would leave (evaluations, and
// seconds estimated from the per-step times).
//
// --map also runs run_map per variant (charges cached across variants) and
// reports the mapping figures and how far each corner's UV moved against
// the first variant, in texels at 1024.
//
// Variant keys: p (fmm_order), theta, leaf, step (fraction of the diagonal),
// eps (start offset in mean source edges, the same for every line; the
// default is 0.03 of each seed's own edge), steps (max_steps),
// stop (stop radius in diagonals from the box centre), trapped, reach (the
// field branch's box stop for a proxy reach of that many diagonals, e.g.
// 0.12: the bounding box grown by kReachMargin x 0.12 diagonals).
// --quick: 12,800 triangles, threads 2.
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>
#include <sstream>

#include "pipeline/field_branch.h"
#include "pipeline/shared_seeds.h"
#include "bench_registry.h"
#include "soupuv/cache/store.h"
#include "soupuv/pipeline.h"
#include "soupuv/geometry/weld.h"
#include "testing/shapes.h"
#include "soupuv/field/intersect.h"
#include "soupuv/field/orient.h"

namespace {

using namespace soupuv;
using Clock = std::chrono::steady_clock;

double cpu_seconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

struct Variant {
  std::string name = "pipeline";
  std::vector<std::pair<std::string, double>> set;
};

Variant parse_variant(const std::string& spec) {
  Variant v;
  const size_t colon = spec.find(':');
  v.name = spec.substr(0, colon);
  if (colon == std::string::npos) return v;
  std::stringstream rest(spec.substr(colon + 1));
  std::string kv;
  while (std::getline(rest, kv, ',')) {
    const size_t eq = kv.find('=');
    if (eq == std::string::npos) throw std::runtime_error("variant key without value: " + kv);
    v.set.emplace_back(kv.substr(0, eq), std::stod(kv.substr(eq + 1)));
  }
  return v;
}

// The variant applied to the map options (trace options as run_map passes
// them: stop_radius 0 leaves run_map's own stop rule in place).
void apply(const Variant& v, MapOptions& o, const Soup& soup, double diag, double mean_edge) {
  for (const auto& [k, x] : v.set) {
    if (k == "p") o.trace.fmm_order = int(x);
    else if (k == "theta") o.trace.fmm_theta = x;
    else if (k == "leaf") o.trace.fmm_leaf_size = int(x);
    else if (k == "step") o.trace.step = x * diag;
    else if (k == "eps") o.trace.start_offset = x * mean_edge;
    else if (k == "steps") o.trace.max_steps = int(x);
    else if (k == "stop") o.trace.stop_radius = x * diag;
    else if (k == "trapped") o.trace.trapped_steps = int(x);
    else if (k == "reach") {
      // The field branch's box stop for a proxy reach of x diagonals.
      o.trace.stop_box = pipeline::stop_box_for(soup, x * diag);
      o.trace.stop_radius = 0.5 * o.trace.stop_box.diagonal() * (1 + 1e-9);
    }
    else throw std::runtime_error("unknown variant key: " + k);
  }
}

// The stop the field branch adds when neither sphere nor box is given: the
// box of the default proxy ladder's reach (field_branch.h). Session 4's
// pipeline stopped at a sphere of 0.75 diagonals instead: `--variant
// sphere:stop=0.75`.
void pipeline_stop(const Soup& soup, field::TraceOptions& o) {
  if (o.stop_radius > 0 || !o.stop_box.empty()) return;
  o.stop_box = pipeline::stop_box_for(soup, pipeline::proxy_reach(soup, map_proxy_defaults()));
  o.stop_radius = 0.5 * o.stop_box.diagonal() * (1 + 1e-9);
}

// Where the time of one trace goes, from the per-step progress reports and
// the traced points: per step index k the active lines (2 evaluations each)
// and those whose step was shortened near the surface (h < full step).
// `stop_box`: with a stop there, the lines still active per step and the
// step times scaled by that share (cost per evaluation as measured per step).
nlohmann::json step_profile(const field::FieldLines& lines, const std::vector<double>& step_seconds,
                            double full_step, const Box3& stop_box) {
  const size_t K = step_seconds.size();
  // Per step: active lines, of them near the surface, of them inside stop_box.
  struct Count { double active = 0, near = 0, boxed = 0; };
  std::vector<Count> count(K);
  auto inside = [&](Vec3 p) {
    return p.x >= stop_box.lo.x && p.y >= stop_box.lo.y && p.z >= stop_box.lo.z &&
           p.x <= stop_box.hi.x && p.y <= stop_box.hi.y && p.z <= stop_box.hi.z;
  };
  for (size_t l = 0; l < lines.size(); ++l) {
    // points: seed, start, then one per step
    const uint32_t b = lines.offsets[l], e = lines.offsets[l + 1];
    bool left = false;
    for (uint32_t j = b + 2; j < e && j - b - 2 < K; ++j) {
      const size_t k = j - b - 2;
      count[k].active += 1;
      if (!left) count[k].boxed += 1;
      left = left || !inside(lines.points[j]);
      if (norm(lines.points[j] - lines.points[j - 1]) < 0.99 * full_step) count[k].near += 1;
    }
  }
  double boxed_seconds = 0, boxed_evaluations = 0;
  for (size_t k = 0; k < K; ++k) {
    if (count[k].active > 0) boxed_seconds += step_seconds[k] * count[k].boxed / count[k].active;
    boxed_evaluations += 2 * count[k].boxed;
  }
  // Least squares: seconds_k ~ a * 2 near_k + b * 2 far_k.
  double snn = 0, snf = 0, sff = 0, sny = 0, sfy = 0;
  double near_evals = 0, far_evals = 0;
  for (size_t k = 0; k < K; ++k) {
    const double n2 = 2 * count[k].near, f2 = 2 * (count[k].active - count[k].near);
    const double y = step_seconds[k];
    snn += n2 * n2; snf += n2 * f2; sff += f2 * f2; sny += n2 * y; sfy += f2 * y;
    near_evals += n2;
    far_evals += f2;
  }
  const double det = snn * sff - snf * snf;
  const double a = det != 0 ? (sny * sff - sfy * snf) / det : 0;
  const double b = det != 0 ? (sfy * snn - sny * snf) / det : 0;
  nlohmann::json per_step = nlohmann::json::array();
  for (size_t k = 0; k < K; ++k)
    per_step.push_back({int(k), int(count[k].active), int(count[k].near), int(count[k].boxed),
                        std::round(1e4 * step_seconds[k]) / 1e4});
  return {{"box_stop_seconds_estimate", boxed_seconds},
          {"box_stop_evaluations", boxed_evaluations},
          {"near_evaluations", near_evals},
          {"far_evaluations", far_evals},
          {"us_per_near_evaluation", 1e6 * a},
          {"us_per_far_evaluation", 1e6 * b},
          {"near_seconds_estimate", a * near_evals},
          {"far_seconds_estimate", b * far_evals},
          {"per_step_k_active_near_boxed_seconds", per_step}};
}

Box3 grown(Box3 box, double d) {
  box.lo = box.lo - Vec3{d, d, d};
  box.hi = box.hi + Vec3{d, d, d};
  return box;
}

int run_field_branch_bench(const bench::Args& args) {
  size_t triangles = args.quick ? 12800 : 100352;
  std::vector<int> thread_counts = args.quick ? std::vector<int>{2} : std::vector<int>{1, 2};
  std::vector<Variant> variants;
  bool map = false;
  for (size_t i = 0; i < args.rest.size(); ++i) {
    const std::string& a = args.rest[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= args.rest.size()) throw std::runtime_error(a + " needs a value");
      return args.rest[++i];
    };
    if (a == "--triangles") triangles = std::stoul(next());
    else if (a == "--variant") variants.push_back(parse_variant(next()));
    else if (a == "--map") map = true;
    else if (a == "--threads") {
      thread_counts.clear();
      std::stringstream s(next());
      std::string t;
      while (std::getline(s, t, ',')) thread_counts.push_back(std::stoi(t));
    } else {
      std::cerr << "field-branch: unknown flag " << a << "\n";
      return 2;
    }
  }
  if (variants.empty()) variants.push_back({});

  const TriMesh mesh = shapes::torus_with(1.0, 0.5, triangles);
  const Soup soup = shapes::to_soup(mesh, 1e-3, 1);
  const double diag = bounding_box(soup).diagonal();
  double edge_sum = 0;
  for (size_t t = 0; t < soup.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) edge_sum += norm(soup.corner(t, k) - soup.corner(t, (k + 1) % 3));
  const double mean_edge = edge_sum / (3.0 * soup.triangles.size());
  std::cerr << "field-branch: torus soup " << soup.triangles.size() << " triangles\n";

  // Charges as the field branch solves them: on the refined soup.
  const MapOptions defaults;
  auto t0 = Clock::now();
  double c0 = cpu_seconds();
  field::IntersectionRefinement refined = field::refine_intersections(soup, Progress::none());
  field::ChargeOptions co = defaults.charge;
  co.threads = *std::max_element(thread_counts.begin(), thread_counts.end());
  const field::ChargeResult charges = field::solve_charges(refined.soup, co, Progress::none());
  bench::emit({{"kind", "charge"},
               {"triangles", soup.triangles.size()},
               {"cut_triangles", refined.cut_triangles},
               {"iterations", charges.iterations},
               {"seconds", std::chrono::duration<double>(Clock::now() - t0).count()},
               {"cpu_seconds", cpu_seconds() - c0}});

  // The shared seeds exactly as field_branch.cpp builds them.
  const geometry::Weld weld =
      geometry::weld_corners(soup, defaults.weld_tolerance * diag, defaults.weld_edge_fraction);
  const field::Orientation orientation =
      field::consistent_orientation(soup, geometry::edge_adjacency(weld, soup.triangles.size()));
  const pipeline::SharedSeeds shared = pipeline::shared_seeds(soup, weld, orientation);
  double max_offset = 0;
  for (double f : map_proxy_defaults().ladder) max_offset = std::max(max_offset, f * diag);

  for (const Variant& v : variants) {
    MapOptions mo;
    apply(v, mo, soup, diag, mean_edge);
    field::TraceOptions to = mo.trace;
    pipeline_stop(soup, to);
    const double full_step = to.step > 0 ? to.step : 0.02 * diag;
    for (int threads : thread_counts) {
      to.threads = threads;
      std::vector<double> step_seconds;
      auto last = Clock::now();
      int last_k = -1;
      // Reports come once per step (throttled to 20/s: a skipped report's
      // time goes to the next reported step).
      Progress progress([&](std::string_view stage, double f) {
        if (stage != "trace" || f >= 1.0 || f < 0.05) return;
        const int k = int(std::lround((f - 0.05) / 0.9 * to.max_steps));
        const auto now = Clock::now();
        if (last_k >= 0 && k > last_k) {
          step_seconds.resize(k, 0.0);
          step_seconds[k - 1] += std::chrono::duration<double>(now - last).count();
        }
        if (k >= last_k) { last = now; last_k = k; }
      });
      field::TraceStats stats;
      const double cpu0 = cpu_seconds();
      auto w0 = Clock::now();
      const field::FieldLines lines =
          field::trace_field_lines(charges, shared.seeds, to, progress, &stats);
      const double wall = std::chrono::duration<double>(Clock::now() - w0).count();
      const double cpu = cpu_seconds() - cpu0;
      // The last step ends at the final report.
      nlohmann::json row = {{"kind", "trace"},
                            {"variant", v.name},
                            {"threads", threads},
                            {"lines", lines.size()},
                            {"corners", 3 * soup.triangles.size()},
                            {"seconds", wall},
                            {"cpu_seconds", cpu},
                            {"build_seconds", stats.build_seconds},
                            {"evaluations", stats.evaluations},
                            {"steps", stats.steps},
                            {"evaluations_per_line", double(stats.evaluations) / double(lines.size())},
                            {"us_per_evaluation", 1e6 * wall / double(stats.evaluations)},
                            {"cpu_us_per_evaluation", 1e6 * cpu / double(stats.evaluations)},
                            {"escaped", stats.escaped},
                            {"step_limit", stats.step_limit},
                            {"stalled", stats.stalled},
                            {"trapped", stats.trapped},
                            {"stop_radius_diagonals", to.stop_radius / diag},
                            {"stop_box", !to.stop_box.empty()},
                            {"step_diagonals", full_step / diag},
                            {"fmm_order", to.fmm_order},
                            {"fmm_theta", to.fmm_theta},
                            {"box_stop_grow_diagonals", 1.25 * max_offset / diag},
                            {"profile", step_profile(lines, step_seconds, full_step,
                                                     grown(bounding_box(soup), 1.25 * max_offset))},
                            {"peak_rss_mb", bench::peak_rss_mb()}};
      bench::emit(row);
      std::cerr << "field-branch: " << v.name << " threads " << threads << ": " << wall << " s, "
                << stats.evaluations << " evaluations\n";
    }
  }

  if (!map) return 0;
  // The mapping figures per variant; charges cached across variants.
  cache::Store store;
  Soup original;
  original.positions = mesh.vertices;
  for (auto f : mesh.faces) original.triangles.push_back({uint32_t(f[0]), uint32_t(f[1]), uint32_t(f[2])});
  original.origins.resize(original.triangles.size());
  std::vector<Vec2> reference;
  for (const Variant& v : variants) {
    MapOptions mo;
    apply(v, mo, soup, diag, mean_edge);
    mo.cache = &store;
    mo.original = &original;
    const double cpu0 = cpu_seconds();
    auto w0 = Clock::now();
    MapResult r = run_map(soup, mo);
    const double wall = std::chrono::duration<double>(Clock::now() - w0).count();
    const auto& d = r.diagnostics;
    nlohmann::json row = {{"kind", "map"},
                          {"variant", v.name},
                          {"seconds", wall},
                          {"cpu_seconds", cpu_seconds() - cpu0},
                          {"stages", d["stages"]},
                          {"trace", d["trace"]},
                          {"uv", {{"coverage", d["uv"]["coverage"]},
                                  {"flipped_fraction", d["uv"]["flipped_fraction"]},
                                  {"stretch_l2", d["uv"]["stretch_l2"]},
                                  {"continuity", d["uv"]["continuity"]},
                                  {"islands", d["uv"]["islands"]}}}};
    if (reference.empty()) {
      reference = r.corner_uvs;
    } else if (reference.size() == r.corner_uvs.size()) {
      std::vector<double> shift(reference.size());
      for (size_t c = 0; c < shift.size(); ++c) shift[c] = 1024 * norm(reference[c] - r.corner_uvs[c]);
      std::sort(shift.begin(), shift.end());
      auto q = [&](double f) { return shift[size_t(f * double(shift.size() - 1))]; };
      row["uv_shift_texels"] = {{"median", q(0.5)}, {"p99", q(0.99)}, {"max", shift.back()},
                                {"over_1_texel", double(std::count_if(shift.begin(), shift.end(),
                                                                      [](double s) { return s > 1; })) /
                                                     double(shift.size())}};
    }
    bench::emit(row);
  }
  return 0;
}

bench::Suite reg("field-branch",
                 "the pipeline's trace alone on the 100k noisy torus soup: TraceStats, cost per "
                 "evaluation near/far, variants of the trace options (--variant, --map)",
                 run_field_branch_bench);

}  // namespace
