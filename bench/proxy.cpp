// soupuv-bench proxy: the offset-mesh proxy (paper §5, §9.1).
//   table1   cylinder r = 1, h = 2 at offsets 10, 5, 3, 2, 1 % (of the extent 2,
//            which reproduces Table 1's sample counts): samples, raw marching-
//            tetrahedra vertices/triangles, final triangles, seconds.
//   soups    the noisy soups in ../shared/data/soups, automatic offset.
//   scaling  a ~100k-triangle noisy soup at resolution 128, 256, 512 (fixed
//            offset): seconds and peak memory, and their log-log slopes.
//   samples  EVERY mesh file in ../shared/data (bad/ excluded) at the
//            defaults (automatic offset, sampling resolution, no cap): one
//            row per file with its checks, rung and seconds; files that do
//            not load (or have no triangles) get a row saying why.
// Flags: --quick (small subset, about a minute), --only=table1|soups|scaling|samples,
//        --resolutions=128,256 (scaling: these instead of the default list),
//        --no-prune (scaling without the cavity pruning, for comparison).
#include <sys/resource.h>

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "bench_registry.h"
#include "soupuv/errors.h"
#include "soupuv/io/load.h"
#include "soupuv/proxy/proxy.h"
#include "testing/shapes.h"

namespace soupuv::bench {
namespace {

// Process CPU seconds (user + sys, all threads): the machine is shared, so
// wall time alone says little.
double cpu_seconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_utime.tv_sec + u.ru_stime.tv_sec + 1e-6 * (u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

// Resets VmHWM so peak_rss_mb() measures one run (Linux clear_refs "5").
void reset_peak_rss() {
  if (FILE* f = std::fopen("/proc/self/clear_refs", "w")) {
    std::fputs("5", f);
    std::fclose(f);
  }
}

nlohmann::json row(const std::string& part, const std::string& mesh, const Soup& soup,
                   const proxy::ProxyResult& r) {
  return {{"suite", "proxy"},
          {"part", part},
          {"mesh", mesh},
          {"triangles_in", soup.triangles.size()},
          {"offset", r.offset},
          {"offset_fraction", r.offset_fraction},
          {"resolution", r.resolution},
          {"seconds", r.seconds},
          {"seconds_grid", r.seconds_grid},
          {"seconds_extract", r.seconds_extract},
          {"seconds_remesh", r.seconds_remesh},
          {"seconds_decimate", r.seconds_decimate},
          {"seconds_smooth", r.seconds_smooth},
          {"seconds_checks", r.seconds_checks},
          {"peak_rss_mb", peak_rss_mb()},
          {"surface_cells", r.surface_cells},
          {"pruned_cells", r.pruned_cells},
          {"distance_evaluations", r.distance_evaluations},
          {"raw_triangles", r.raw_triangles},
          {"collapsed_triangles", r.collapsed_triangles},
          {"proxy_triangles", r.triangles},
          {"proxy_vertices", r.vertices},
          {"closed", r.closed},
          {"manifold", r.manifold},
          {"outward", r.outward},
          {"genus", r.genus},
          {"outer_components", r.outer_components},
          {"inner_components", r.inner_components},
          {"encloses", r.encloses},
          {"min_distance_ratio", r.min_distance_ratio},
          {"self_intersections", r.self_intersections},
          {"self_intersections_checked", r.self_intersections_checked},
          {"threads", threads()},
          {"warnings", r.warnings}};
}

void table1(bool quick) {
  Soup soup = shapes::to_soup(shapes::cylinder(1.0, 2.0, 256, 32, 32));
  std::vector<double> percents = quick ? std::vector<double>{10} : std::vector<double>{10, 5, 3, 2, 1};
  for (double pct : percents) {
    proxy::ProxyOptions o;
    o.offset_mode = proxy::OffsetMode::absolute;
    o.offset = pct / 100 * 2.0;
    // Table 1 counts marching-cubes output: report the raw level set, and the
    // remeshed proxy in a second row.
    for (bool remesh : {false, true}) {
      o.remesh = remesh;
      o.smoothing_iterations = remesh ? 10 : 0;
      reset_peak_rss();
      auto r = proxy::build_proxy(soup, o);
      auto j = row(remesh ? "table1_remeshed" : "table1_raw", "cylinder_r1_h2", soup, r);
      j["offset_percent"] = pct;
      j["samples"] = r.resolution;
      emit(j);
    }
  }
}

void soups(bool quick) {
  std::string dir = std::string(SOUPUV_SHARED_DATA) + "/soups";
  std::vector<std::string> names = quick ? std::vector<std::string>{"suzanne"}
                                         : std::vector<std::string>{"suzanne", "spot", "teapot", "fandisk",
                                                                    "stanford-bunny"};
  for (const auto& name : names) {
    std::string path = dir + "/" + name + "-soup.glb";
    if (!std::filesystem::exists(path)) {
      std::cerr << "proxy bench: missing " << path << "\n";
      continue;
    }
    Soup soup = io::load_file(path).soup;
    proxy::ProxyOptions o;  // automatic offset, sampling resolution
    if (quick) o.max_resolution = 96;
    reset_peak_rss();
    auto r = proxy::build_proxy(soup, o);
    auto j = row("soups", name, soup, r);
    j["ladder_tried"] = r.ladder_tried;
    emit(j);
  }
}

void scaling(bool quick, std::vector<int> resolutions, bool prune) {
  Soup soup = shapes::to_soup(shapes::sphere_with(1.0, quick ? 10000 : 100000), 1e-3, 1);
  // The surface area is fixed, so surface cells grow with resolution^2.
  if (resolutions.empty())
    resolutions = quick ? std::vector<int>{48, 96} : std::vector<int>{128, 256, 512};
  std::vector<double> res, secs, mem;
  for (int n : resolutions) {
    proxy::ProxyOptions o;
    o.offset_mode = proxy::OffsetMode::relative;
    o.offset = quick ? 0.02 : 0.01;  // quick: coarser grids need a larger offset
    o.resolution = n;
    // Target edge length stays the default (the offset): the proxy needs no
    // more triangles at a finer grid, only a more accurate level set.
    o.prune_cavities = prune;
    reset_peak_rss();
    double cpu0 = cpu_seconds();
    auto r = proxy::build_proxy(soup, o);
    auto j = row("scaling", quick ? "sphere_10k_noisy" : "sphere_100k_noisy", soup, r);
    j["cpu_seconds"] = cpu_seconds() - cpu0;
    j["prune_cavities"] = prune;
    emit(j);
    res.push_back(n);
    secs.push_back(r.seconds);
    mem.push_back(j["peak_rss_mb"].get<double>());
  }
  emit({{"suite", "proxy"}, {"kind", "summary"}, {"part", "scaling"},
        {"seconds_vs_resolution_loglog_slope", loglog_slope(res, secs)},
        {"peak_rss_vs_resolution_loglog_slope", loglog_slope(res, mem)},
        {"note", "slope 2 = grows with the surface; 3 would be the volume"}});
}

// Every glTF/GLB/Draco file under ../shared/data except bad/, sorted.
std::vector<std::filesystem::path> sample_files() {
  namespace fs = std::filesystem;
  std::vector<fs::path> out;
  fs::path root = fs::path(SOUPUV_SHARED_DATA);
  for (const auto& e : fs::recursive_directory_iterator(root)) {
    if (!e.is_regular_file()) continue;
    std::string ext = e.path().extension().string();
    if (ext != ".glb" && ext != ".gltf" && ext != ".drc") continue;
    if (fs::relative(e.path(), root).string().rfind("bad", 0) == 0) continue;
    out.push_back(e.path());
  }
  std::sort(out.begin(), out.end());
  return out;
}

void samples(bool quick) {
  namespace fs = std::filesystem;
  int ok = 0, failed = 0, skipped = 0;
  for (const fs::path& path : sample_files()) {
    std::string name = fs::relative(path, fs::path(SOUPUV_SHARED_DATA)).string();
    io::LoadOptions load;
    load.allow_external_uris = true;
    load.base_dir = path.parent_path().string();
    Soup soup;
    try {
      soup = io::load_file(path.string(), load).soup;
    } catch (const Error& e) {
      // Not a triangle mesh (points, lines, empty): nothing to wrap.
      emit({{"suite", "proxy"}, {"part", "samples"}, {"mesh", name}, {"loaded", false}, {"error", e.what()}});
      ++skipped;
      continue;
    }
    // Quick: a smoke test (files under 5,000 triangles, resolution capped at
    // 64), so the whole --quick run stays about a minute.
    if (quick && soup.triangles.size() > 5000) continue;
    proxy::ProxyOptions o;  // the defaults: automatic offset, sampling resolution, no cap
    if (quick) o.max_resolution = 64;
    reset_peak_rss();
    double cpu0 = cpu_seconds();
    auto r = proxy::build_proxy(soup, o);
    auto j = row("samples", name, soup, r);
    j["loaded"] = true;
    j["cpu_seconds"] = cpu_seconds() - cpu0;
    j["ladder_tried"] = r.ladder_tried;
    j["ok"] = r.ok() && r.outer_components == 1 && r.min_distance_ratio >= 0.5;
    emit(j);
    (j["ok"].get<bool>() ? ok : failed)++;
  }
  emit({{"suite", "proxy"}, {"kind", "summary"}, {"part", "samples"}, {"ok", ok}, {"failed", failed},
        {"not_loaded", skipped},
        {"note", "ok = closed, manifold, outward, one outer component, encloses, no self-intersections, "
                 "min distance >= 0.5 o"}});
}

int run_proxy(const Args& args) {
  std::string only;
  bool prune = true;  // --no-prune: scaling builds the cavity shell too (the old way)
  std::vector<int> resolutions;
  for (const auto& a : args.rest) {
    if (a.rfind("--only=", 0) == 0) only = a.substr(7);
    if (a == "--no-prune") prune = false;
    if (a.rfind("--resolutions=", 0) == 0) {
      std::stringstream list(a.substr(14));
      for (std::string item; std::getline(list, item, ',');) resolutions.push_back(std::stoi(item));
    }
  }
  try {
    if (only.empty() || only == "table1") table1(args.quick);
    if (only.empty() || only == "soups") soups(args.quick);
    if (only.empty() || only == "scaling") scaling(args.quick, resolutions, prune);
    if (only.empty() || only == "samples") samples(args.quick);
  } catch (const Error& e) {
    std::cerr << "proxy bench: " << e.what() << "\n";
    return 1;
  }
  return 0;
}

Suite reg("proxy", "offset-mesh proxy: Table 1 cylinder, shared soups, resolution scaling",
          run_proxy);

}  // namespace
}  // namespace soupuv::bench
