// UV method dispatch for `soupuv map` (see uv_method.h): flags -> MapOptions
// -> soupuv::run_map, plus the optional debug files.
#include "uv_method.h"

#include <algorithm>
#include <fstream>
#include <memory>

#include "cli.h"
#include "soupuv/cache/store.h"
#include "soupuv/errors.h"
#include "soupuv/io/load.h"
#include "soupuv/io/texture.h"
#include "soupuv/quality/uv_layout.h"

namespace soupuv::cli {

namespace {

double number(const std::string& flag, const std::string& v) {
  try {
    size_t used = 0;
    double x = std::stod(v, &used);
    if (used != v.size()) throw std::invalid_argument(v);
    return x;
  } catch (const std::exception&) {
    throw UsageError{flag + " needs a number, not '" + v + "'"};
  }
}

int integer(const std::string& flag, const std::string& v, int lo, int hi) {
  double x = number(flag, v);
  if (x != double(int(x)) || x < lo || x > hi)
    throw UsageError{flag + " needs a whole number in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]"};
  return int(x);
}

std::vector<atlas::SeamHint> read_seam_hints(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw IoError{"cannot read seam hints " + path};
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(in);
  } catch (const std::exception& e) {
    throw Error(ErrorCode::invalid_input, "seam hints " + path + ": " + e.what());
  }
  std::vector<atlas::SeamHint> hints;
  if (!j.is_array()) throw Error(ErrorCode::invalid_input, "seam hints: an array of polylines expected");
  for (const auto& line : j) {
    atlas::SeamHint h;
    if (!line.is_array()) throw Error(ErrorCode::invalid_input, "seam hints: a polyline is an array of [x,y,z]");
    for (const auto& p : line) {
      if (!p.is_array() || p.size() != 3 || !p[0].is_number() || !p[1].is_number() || !p[2].is_number())
        throw Error(ErrorCode::invalid_input, "seam hints: a point is [x,y,z]");
      h.points.push_back({p[0].get<double>(), p[1].get<double>(), p[2].get<double>()});
    }
    hints.push_back(std::move(h));
  }
  return hints;
}

void write_bytes(const std::string& path, const std::vector<uint8_t>& bytes) {
  write_file_atomically(path, bytes.data(), bytes.size());
}

}  // namespace

bool parse_method_flag(const std::vector<std::string>& args, size_t& i, MethodFlags& f) {
  const std::string& a = args[i];
  auto value = [&]() -> const std::string& {
    if (i + 1 >= args.size()) throw UsageError{a + " needs a value"};
    return args[++i];
  };
  MapOptions& o = f.options;
  if (a == "--offset") {
    const std::string& v = value();
    if (v == "auto") {
      o.proxy.offset_mode = proxy::OffsetMode::automatic;
    } else {
      o.proxy.offset_mode = proxy::OffsetMode::relative;
      o.proxy.offset = number(a, v);
      if (!(o.proxy.offset > 0 && o.proxy.offset < 1)) throw UsageError{"--offset needs auto or a fraction in (0, 1)"};
    }
  } else if (a == "--offset-abs") {
    o.proxy.offset_mode = proxy::OffsetMode::absolute;
    o.proxy.offset = number(a, value());
    if (!(o.proxy.offset > 0)) throw UsageError{"--offset-abs needs a positive length"};
  } else if (a == "--resolution") {
    o.proxy.resolution = integer(a, value(), 0, 2048);
  } else if (a == "--proxy-edge") {
    o.proxy.target_edge_length = number(a, value());
    if (!(o.proxy.target_edge_length >= 0)) throw UsageError{"--proxy-edge needs a length >= 0 (0: auto)"};
  } else if (a == "--chart-angle") {
    o.atlas.max_normal_deviation_deg = number(a, value());
    if (!(o.atlas.max_normal_deviation_deg > 0 && o.atlas.max_normal_deviation_deg <= 90))
      throw UsageError{"--chart-angle needs degrees in (0, 90]"};
  } else if (a == "--merge-charts") {
    o.atlas.merge_charts = true;
  } else if (a == "--no-merge-charts") {
    o.atlas.merge_charts = false;
  } else if (a == "--no-relax-seams") {
    o.atlas.relax_seams = false;
  } else if (a == "--relax-seams") {
    o.atlas.relax_seams = true;
    o.relax_max_soup_per_proxy_face = 0;
  } else if (a == "--merge-area") {
    o.atlas.merge_max_area_fraction = number(a, value());
    if (!(o.atlas.merge_max_area_fraction > 0 && o.atlas.merge_max_area_fraction <= 1))
      throw UsageError{"--merge-area needs a fraction in (0, 1]"};
  } else if (a == "--merge-cone") {
    o.atlas.merge_max_normal_deviation_deg = number(a, value());
    if (!(o.atlas.merge_max_normal_deviation_deg > 0 && o.atlas.merge_max_normal_deviation_deg <= 180))
      throw UsageError{"--merge-cone needs degrees in (0, 180]"};
  } else if (a == "--merge-fill") {
    o.atlas.merge_min_fill = number(a, value());
    if (!(o.atlas.merge_min_fill >= 0 && o.atlas.merge_min_fill <= 1))
      throw UsageError{"--merge-fill needs a fraction in [0, 1]"};
  } else if (a == "--chart-stretch") {
    o.atlas.max_stretch = number(a, value());
    if (!(o.atlas.max_stretch >= 1)) throw UsageError{"--chart-stretch needs a value >= 1"};
  } else if (a == "--weld-tolerance") {
    o.weld_tolerance = number(a, value());
    if (!(o.weld_tolerance >= 0 && o.weld_tolerance < 0.1)) throw UsageError{"--weld-tolerance needs a fraction of the diagonal in [0, 0.1)"};
  } else if (a == "--pack-splits") {
    o.atlas.packing_split_rounds = integer(a, value(), 0, 16);
  } else if (a == "--steps") {
    o.trace.max_steps = integer(a, value(), 1, 100000);
  } else if (a == "--integrator") {
    const std::string& v = value();
    if (v == "euler") o.trace.integrator = field::TraceOptions::Integrator::euler;
    else if (v == "midpoint") o.trace.integrator = field::TraceOptions::Integrator::midpoint;
    else throw UsageError{"--integrator must be euler or midpoint"};
  } else if (a == "--solver") {
    const std::string& v = value();
    if (v == "krylov") o.charge.solver = field::ChargeOptions::Solver::krylov;
    else if (v == "robin-hood") o.charge.solver = field::ChargeOptions::Solver::robin_hood;
    else throw UsageError{"--solver must be krylov or robin-hood"};
  } else if (a == "--tolerance") {
    o.charge.tolerance = number(a, value());
    if (!(o.charge.tolerance > 0 && o.charge.tolerance < 1)) throw UsageError{"--tolerance must be in (0, 1)"};
  } else if (a == "--threads") {
    o.threads = integer(a, value(), 1, 1024);
  } else if (a == "--cache-dir") {
    f.cache_dir = value();
  } else if (a == "--debug-prefix") {
    f.debug_prefix = value();
  } else if (a == "--uv-layout") {
    f.uv_layout = value();
  } else if (a == "--original") {
    f.original = value();
  } else if (a == "--seam-hints") {
    f.seam_hints = value();
  } else if (a == "--no-refine-intersections") {
    o.refine_intersections = false;
  } else if (a == "--no-orient") {
    o.orient_sides = false;
  } else if (a == "--no-chart-neighbours") {
    o.chart_fix_neighbours = false;
  } else if (a == "--no-share-lines") {
    o.share_lines = false;
  } else if (a == "--uv-repair") {
    o.uv_repair = true;
  } else if (a == "--no-uv-repair") {
    o.uv_repair = false;
  } else if (a == "--repair-growth") {
    o.repair.max_growth = integer(a, value(), 0, 20);
  } else if (a == "--no-untangle") {
    o.repair.untangle = false;
  } else if (a == "--no-grow-while-bad") {
    o.repair.grow_while_bad = false;
  } else if (a == "--no-island-start") {
    o.repair.island_start = false;
  } else if (a == "--no-repair-split") {
    o.repair_split_triangles = false;
  } else if (a == "--no-strict-retry") {
    o.repair_strict_retry = 0;
  } else if (a == "--strict-retry") {
    o.repair_strict_retry = number(a, value());
  } else if (a == "--weld-corners") {
    o.weld_by_edges = false;
  } else if (a == "--seed-weld-corners") {
    o.seed_weld_by_edges = false;
  } else if (a == "--seed-edge-fraction") {
    o.seed_weld_edge_fraction = number(a, value());
    if (!(o.seed_weld_edge_fraction >= 0)) throw UsageError{"--seed-edge-fraction needs a value >= 0"};
  } else if (a == "--repair-weld-lines") {
    o.repair_weld_lines = true;
  } else if (a == "--no-reweld") {
    o.uv_reweld = false;
  } else if (a == "--no-island-relax") {
    o.island_relax = false;
  } else if (a == "--island-max-triangles") {
    o.island_relax_max_triangles = size_t(number(a, value()));
  } else if (a == "--reweld-density") {
    o.reweld.max_energy_density = number(a, value());
    if (!(o.reweld.max_energy_density >= 4)) throw UsageError{"--reweld-density needs a value >= 4"};
  } else if (a == "--repair-stretch") {
    o.repair.stretch_threshold = number(a, value());
    if (!(o.repair.stretch_threshold > 1)) throw UsageError{"--repair-stretch needs a factor > 1"};
  } else if (a == "--no-candidates") {
    o.candidates.resize(std::min<size_t>(o.candidates.size(), 1));
  } else if (a == "--candidate") {
    try {
      o.candidates.push_back(parse_map_candidate(value()));
    } catch (const Error& e) {
      throw UsageError{std::string("--candidate: ") + e.what()};
    }
  } else if (a == "--candidate-max-triangles") {
    o.candidates_max_triangles = size_t(integer(a, value(), 0, 100000000));
  } else if (a == "--no-uv-solve") {
    o.soup_uv_solve = false;
  } else if (a == "--uv-collapse-ratio") {
    o.uv_solve.collapse_ratio = number(a, value());
    if (!(o.uv_solve.collapse_ratio >= 0 && o.uv_solve.collapse_ratio < 1))
      throw UsageError{"--uv-collapse-ratio needs a value in [0, 1)"};
  } else if (a == "--uv-untangle-iterations") {
    o.uv_solve.untangle_iterations = integer(a, value(), 0, 1000);
  } else if (a == "--uv-solve-iterations") {
    o.uv_solve.solve_iterations = integer(a, value(), 0, 1000);
  } else if (a == "--uv-overlap-samples") {
    o.uv_solve.overlap_samples_per_texel = number(a, value());
    if (!(o.uv_solve.overlap_samples_per_texel >= 0.25 && o.uv_solve.overlap_samples_per_texel <= 8))
      throw UsageError{"--uv-overlap-samples needs a value in [0.25, 8]"};
  } else if (a == "--no-chart-fix") {
    o.transfer.fix_chart_boundaries = false;
  } else {
    return false;
  }
  return true;
}

MethodRun compute_uvs(const io::Asset& asset, const std::string& method, const MethodFlags& flags,
                      Progress& progress) {
  MapOptions options = flags.options;
  if (method == "box") options.method = MapMethod::box;
  else if (method == "field") options.method = MapMethod::field;
  else throw UsageError{"--method must be box or field, not '" + method + "'"};

  std::unique_ptr<cache::Store> store;
  if (!flags.cache_dir.empty()) {
    store = std::make_unique<cache::Store>(cache::StoreOptions{.memory_bytes = size_t(256) << 20,
                                                               .directory = flags.cache_dir});
    options.cache = store.get();
  }
  io::Asset original;
  if (!flags.original.empty()) {
    original = io::load_file(flags.original);
    options.original = &original.soup;
  }
  if (!flags.seam_hints.empty()) options.atlas.seam_hints = read_seam_hints(flags.seam_hints);
  options.keep_debug = !flags.debug_prefix.empty();

  MapResult result = run_map(asset, options, progress);
  MethodRun run;
  run.corner_uvs = std::move(result.corner_uvs);
  run.diagnostics = std::move(result.diagnostics);

  if (!flags.uv_layout.empty()) write_bytes(flags.uv_layout, quality::uv_layout_png(run.corner_uvs, 1024));
  if (!flags.debug_prefix.empty()) {
    const std::string& p = flags.debug_prefix;
    write_bytes(p + ".uv.png", quality::uv_layout_png(run.corner_uvs, 1024));
    if (options.method == MapMethod::field) {
      write_bytes(p + ".proxy.glb", proxy_debug_glb(result.debug, io::uv_check_texture(1024).bytes));
      write_bytes(p + ".lines.glb", field_lines_glb(result.debug.lines));
    }
    run.diagnostics["debug_outputs"] = {{"prefix", p}};
  }
  return run;
}

}  // namespace soupuv::cli
