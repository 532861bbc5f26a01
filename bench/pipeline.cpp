// soupuv-bench pipeline [--quick] [--only NAME] [--offset F]: the whole mapping job on the
// shared noisy soups and on large synthetic soups, field method vs the box
// baseline side by side, and a re-run with a new proxy offset that reuses the
// cached charges and field lines (the issue's >= 5x target).
//
// Rows: suite, mesh, triangles, method ("field", "field-rerun", "box"),
// seconds, threads, peak_rss_mb, per-stage seconds, and the uv metrics
// (coverage, flipped_fraction, stretch_l2, continuity, continuity_1texel,
// islands; stretch_median and stretch_l2_worst1pct_share are companions to
// read stretch_l2 by, not replacements). Summary: rerun speedups and field-vs-box ratios per mesh.
#include <chrono>
#include <iostream>

#include "bench_registry.h"
#include "soupuv/cache/store.h"
#include "soupuv/io/load.h"
#include "soupuv/pipeline.h"
#include "soupuv/shapes.h"

namespace {

using namespace soupuv;
using Clock = std::chrono::steady_clock;

struct Input {
  std::string name;
  Soup soup;
  Soup original;       // welded reference with the same triangle order
  bool has_original = false;
};

Soup welded(const TriMesh& m) {
  Soup s;
  s.positions = m.vertices;
  for (auto f : m.faces) s.triangles.push_back({uint32_t(f[0]), uint32_t(f[1]), uint32_t(f[2])});
  s.origins.resize(s.triangles.size());
  return s;
}

Input synthetic(const std::string& name, const TriMesh& mesh) {
  return {name, shapes::to_soup(mesh, 1e-3, 1), welded(mesh), true};
}

Input shared(const std::string& name) {
  std::string dir = std::string(SOUPUV_SHARED_DATA) + "/soups/";
  Input in{name, io::load_file(dir + name + "-soup.glb").soup, {}, true};
  in.original = io::load_file(dir + name + "-soup.original.glb").soup;
  return in;
}

nlohmann::json row(const Input& in, const std::string& method, double seconds, const nlohmann::json& d) {
  nlohmann::json r = {{"suite", "pipeline"},
                      {"mesh", in.name},
                      {"triangles", in.soup.triangles.size()},
                      {"method", method},
                      {"seconds", seconds},
                      {"threads", bench::threads()},
                      {"peak_rss_mb", bench::peak_rss_mb()}};
  for (const char* k : {"coverage", "flipped_fraction", "stretch_l2", "stretch_median",
                        "stretch_l2_worst1pct_share", "continuity", "continuity_1texel", "islands"})
    if (d["uv"].contains(k)) r[k] = d["uv"][k];
  nlohmann::json stages = nlohmann::json::object();
  for (auto& [name, s] : d["stages"].items()) stages[name] = s["seconds"];
  r["stages"] = stages;
  if (d.contains("trace")) {
    r["hit_fraction"] = d["trace"]["hit_fraction"];
    r["fallback"] = d["trace"]["fallback"];
    r["charts"] = d["atlas"]["charts"];
    r["proxy_triangles"] = d["proxy"].value("triangles", 0);
    r["cache_hits"] = d["cache"]["hits"];
    r["mixed_side_after"] = d["orient"].value("mixed_side_triangles_after", 0);
    r["corrected_triangles"] = d["transfer"]["corrected_triangles"];
    r["lines"] = d["trace"]["lines"];
    r["causes"] = d["uv"]["causes"];
  }
  return r;
}

int run_pipeline(const bench::Args& args) {
  std::string only;
  double offset = 0;  // 0: the pipeline's default offset
  for (size_t i = 0; i + 1 < args.rest.size(); ++i) {
    if (args.rest[i] == "--only") only = args.rest[i + 1];
    if (args.rest[i] == "--offset") offset = std::stod(args.rest[i + 1]);
  }

  // --quick (CI, about a minute): one small sphere with a fixed offset (the
  // automatic offset's ladder alone takes minutes on a loaded machine).
  std::vector<std::string> names = args.quick
      ? std::vector<std::string>{"sphere-500"}
      : std::vector<std::string>{"suzanne", "spot", "teapot", "fandisk", "stanford-bunny", "torus-100k"};
  nlohmann::json summary = {{"suite", "pipeline"}, {"kind", "summary"}, {"quick", args.quick}};
  for (const std::string& name : names) {
    if (!only.empty() && name != only) continue;
    Input in = name == "sphere-500"   ? synthetic(name, shapes::sphere_with(1.0, 500))
               : name == "torus-100k" ? synthetic(name, shapes::torus_with(1.0, 0.5, 100352))
                                      : shared(name);
    std::cerr << "pipeline: " << name << " (" << in.soup.triangles.size() << " triangles)\n";
    cache::Store store;
    MapOptions o;
    o.cache = &store;
    o.original = in.has_original ? &in.original : nullptr;
    if (args.quick || offset > 0) {
      o.proxy.offset_mode = proxy::OffsetMode::relative;
      o.proxy.offset = offset > 0 ? offset : 0.03;
    }

    auto t0 = Clock::now();
    MapResult first = run_map(in.soup, o);
    double s_first = std::chrono::duration<double>(Clock::now() - t0).count();
    bench::emit(row(in, "field", s_first, first.diagnostics));

    // Same soup, same field parameters, a 1.5x larger proxy offset.
    o.proxy.offset_mode = proxy::OffsetMode::absolute;
    o.proxy.offset = 1.5 * first.diagnostics["proxy"]["offset"].get<double>();
    auto t1 = Clock::now();
    MapResult again = run_map(in.soup, o);
    double s_again = std::chrono::duration<double>(Clock::now() - t1).count();
    bench::emit(row(in, "field-rerun", s_again, again.diagnostics));

    MapOptions box = o;
    box.method = MapMethod::box;
    box.cache = nullptr;
    auto t2 = Clock::now();
    MapResult b = run_map(in.soup, box);
    double s_box = std::chrono::duration<double>(Clock::now() - t2).count();
    bench::emit(row(in, "box", s_box, b.diagnostics));

    // The rerun skips charge and trace; what stays is proxy + atlas +
    // transfer, so the speedup is (charge + trace) dominated.
    summary["meshes"][name] = {
        {"triangles", in.soup.triangles.size()},
        {"field_seconds", s_first},
        {"rerun_seconds", s_again},
        {"rerun_speedup", s_first / s_again},
        {"field_continuity", first.diagnostics["uv"]["continuity"]},
        {"box_continuity", b.diagnostics["uv"]["continuity"]},
        {"field_islands", first.diagnostics["uv"]["islands"]},
        {"box_islands", b.diagnostics["uv"]["islands"]},
        {"field_stretch_l2", first.diagnostics["uv"]["stretch_l2"]},
        {"field_flipped_fraction", first.diagnostics["uv"]["flipped_fraction"]}};
  }
  bench::emit(summary);
  return 0;
}

bench::Suite reg("pipeline",
                 "end to end: field vs box on the shared soups and a 100k soup; cached re-run with a new offset",
                 run_pipeline);

}  // namespace
