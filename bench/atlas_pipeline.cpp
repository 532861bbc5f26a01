// soupuv-bench atlas-pipeline: atlas variants judged by what the mapping job
// makes of them — continuity, flips and stretch of the textured soup — not by
// the atlas's own figures. Every variant of one sample reuses the same charges
// and field lines (one in-memory cache per sample: the field never looks at
// the proxy), so a variant costs proxy + atlas + transfer only.
//
//   --only NAME[,NAME]   samples (shared noisy soups suzanne spot teapot
//                        fandisk stanford-bunny; glTF/Draco Duck CesiumMan Fox
//                        bunny-drc); default: all but the two bunnies.
//   --variant NAME:K=V,K=V   an atlas variant on top of map_atlas_defaults()
//                        (repeatable; default: the pipeline's atlas alone).
//                        Keys: angle (max_normal_deviation_deg), stretch
//                        (max_stretch), merge (0/1), merge_crease,
//                        merge_area, merge_fill, merge_cone
//                        (merge_max_normal_deviation_deg), pack_splits,
//                        split_below, relax (0/1: seam relaxation),
//                        relax_band, relax_stretch, relax_narrow, soup_weights (0/1: seam weights from
//                        the soup's edge density, with relax),
//                        offset (proxy offset, fraction of the diagonal;
//                        default: auto), proxy_edge (proxy remeshing edge
//                        length, fraction of the diagonal; default: the
//                        offset).
//   --quick              suzanne and Fox, the pipeline's atlas only.
//
// One JSON line per (sample, variant) with the uv figures, the atlas's
// charts / utilisation / seam length and the discontinuity causes; then one
// summary line per variant (mean and worst continuity, worst flips).
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <iostream>
#include <sstream>

#include "bench_registry.h"
#include "soupuv/cache/store.h"
#include "soupuv/errors.h"
#include "soupuv/io/load.h"
#include "soupuv/pipeline.h"

namespace {

using namespace soupuv;

struct Sample {
  std::string name;
  std::string file;      // under SOUPUV_SHARED_DATA
  bool noisy_soup;       // has NAME-soup.original.glb for continuity
};

const std::vector<Sample> kSamples = {
    {"suzanne", "soups/suzanne-soup.glb", true},   {"spot", "soups/spot-soup.glb", true},
    {"teapot", "soups/teapot-soup.glb", true},     {"fandisk", "soups/fandisk-soup.glb", true},
    {"stanford-bunny", "soups/stanford-bunny-soup.glb", true},
    {"Duck", "gltf/Duck.glb", false},              {"CesiumMan", "gltf/CesiumMan.glb", false},
    {"Fox", "gltf/Fox/Fox.gltf", false},           {"bunny-drc", "drc/bunny_gltf.drc", false}};

struct Variant {
  std::string name;
  atlas::AtlasOptions atlas = map_atlas_defaults();
  double offset = 0;      // 0: the pipeline's automatic offset
  double proxy_edge = 0;  // 0: the proxy's own choice (the offset)
};

// "NAME:K=V,K=V" -> a variant of the pipeline's atlas.
Variant parse_variant(const std::string& text) {
  Variant v;
  const size_t colon = text.find(':');
  v.name = text.substr(0, colon);
  if (colon == std::string::npos) return v;
  std::stringstream list(text.substr(colon + 1));
  std::string item;
  while (std::getline(list, item, ',')) {
    const size_t eq = item.find('=');
    if (eq == std::string::npos) throw Error(ErrorCode::invalid_input, "variant item without '=': " + item);
    const std::string key = item.substr(0, eq);
    const double value = std::stod(item.substr(eq + 1));
    atlas::AtlasOptions& a = v.atlas;
    if (key == "angle") a.max_normal_deviation_deg = value;
    else if (key == "stretch") a.max_stretch = value;
    else if (key == "merge") a.merge_charts = value != 0;
    else if (key == "merge_crease") a.merge_crease_deg = value;
    else if (key == "merge_area") a.merge_max_area_fraction = value;
    else if (key == "merge_fill") a.merge_min_fill = value;
    else if (key == "merge_cone") a.merge_max_normal_deviation_deg = value;
    else if (key == "pack_splits") a.packing_split_rounds = int(value);
    else if (key == "split_below") a.packing_split_below = value;
    else if (key == "relax") a.relax_seams = value != 0;
    else if (key == "relax_band") a.relax_band = value;
    else if (key == "relax_stretch") a.relax_max_stretch_increase = value;
    else if (key == "relax_narrow") a.relax_narrowings = int(value);
    else if (key == "soup_weights") a.soup_seam_weights = value != 0;
    else if (key == "offset") v.offset = value;
    else if (key == "proxy_edge") v.proxy_edge = value;
    else throw Error(ErrorCode::invalid_input, "unknown variant key: " + key);
  }
  return v;
}

double cpu_seconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

int run_atlas_pipeline(const bench::Args& args) {
  std::vector<std::string> only;
  std::vector<Variant> variants;
  for (size_t i = 0; i + 1 < args.rest.size(); ++i) {
    if (args.rest[i] == "--only") {
      std::stringstream list(args.rest[i + 1]);
      for (std::string n; std::getline(list, n, ',');) only.push_back(n);
    }
    if (args.rest[i] == "--variant") variants.push_back(parse_variant(args.rest[i + 1]));
  }
  if (variants.empty()) variants.push_back(parse_variant("pipeline"));
  if (args.quick && only.empty()) only = {"suzanne", "Fox"};
  if (only.empty())
    for (const Sample& s : kSamples)
      if (s.name.find("bunny") == std::string::npos) only.push_back(s.name);

  struct Tally {
    double sum = 0, worst = 1, worst_flips = 0, worst_l2 = 0;
    int n = 0;
  };
  std::vector<Tally> tally(variants.size());
  for (const Sample& s : kSamples) {
    if (std::find(only.begin(), only.end(), s.name) == only.end()) continue;
    io::LoadOptions lo;
    lo.allow_external_uris = true;  // Fox keeps its buffer beside the .gltf
    const std::string path = std::string(SOUPUV_SHARED_DATA) + "/" + s.file;
    const Soup soup = io::load_file(path, lo).soup;
    Soup original;
    if (s.noisy_soup) {
      std::string o = path;
      o.replace(o.size() - 4, 4, ".original.glb");
      original = io::load_file(o).soup;
    }
    cache::Store store;  // the field branch runs once per sample
    for (size_t v = 0; v < variants.size(); ++v) {
      std::cerr << "atlas-pipeline: " << s.name << " / " << variants[v].name << "\n";
      MapOptions o;
      o.atlas = variants[v].atlas;
      o.cache = &store;
      o.original = s.noisy_soup ? &original : nullptr;
      if (variants[v].offset > 0) {
        o.proxy.offset_mode = proxy::OffsetMode::relative;
        o.proxy.offset = variants[v].offset;
      }
      if (variants[v].proxy_edge > 0) {
        o.proxy.target_edge_length = variants[v].proxy_edge * bounding_box(soup).diagonal();
      }
      const double c0 = cpu_seconds();
      const auto t0 = std::chrono::steady_clock::now();
      MapResult r = run_map(soup, o);
      const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      const nlohmann::json& d = r.diagnostics;
      const nlohmann::json& uv = d["uv"];
      const nlohmann::json& a = d["atlas"];
      nlohmann::json row = {{"suite", "atlas-pipeline"},
                            {"mesh", s.name},
                            {"variant", variants[v].name},
                            {"triangles", soup.triangles.size()},
                            {"continuity", uv["continuity"]},
                            {"continuity_1texel", uv["continuity_1texel"]},
                            {"flipped_fraction", uv["flipped_fraction"]},
                            {"stretch_l2", uv["stretch_l2"]},
                            {"stretch_median", uv["stretch_median"]},
                            {"islands", uv["islands"]},
                            {"discontinuous", uv["causes"]["discontinuous"]},
                            {"pairs", uv["causes"]["pairs"]},
                            {"from_chart_seams", uv["causes"]["chart_correction"]},
                            {"proxy_triangles", d["proxy"]["triangles"]},
                            {"charts", a["charts"]},
                            {"utilization", a["utilization"]},
                            {"seam_length_relative", a["seam_length_relative"]},
                            {"seam_cost_before_relax", a["seam_cost_before_relax"]},
                            {"seam_cost", a["seam_cost"]},
                            {"relaxed_pairs", a["relaxed_pairs"]},
                            {"atlas_seconds", a["seconds"]},
                            {"seconds", seconds},
                            {"cpu_seconds", cpu_seconds() - c0},
                            {"field_cached", d["cache"]["hits"].get<double>() > 0}};
      row["causes"] = uv["causes"];
      if (d.contains("uv_repair") && d["uv_repair"].value("enabled", false))
        row["before_repair"] = d["uv_repair"]["before"];
      bench::emit(row);
      Tally& t = tally[v];
      const double c = uv["continuity"].get<double>();
      t.sum += c;
      t.worst = std::min(t.worst, c);
      t.worst_flips = std::max(t.worst_flips, uv["flipped_fraction"].get<double>());
      t.worst_l2 = std::max(t.worst_l2, uv["stretch_l2"].get<double>());
      ++t.n;
    }
  }
  for (size_t v = 0; v < variants.size(); ++v)
    bench::emit({{"suite", "atlas-pipeline"},
                 {"kind", "summary"},
                 {"variant", variants[v].name},
                 {"samples", tally[v].n},
                 {"mean_continuity", tally[v].n ? tally[v].sum / tally[v].n : 0},
                 {"worst_continuity", tally[v].worst},
                 {"worst_flipped_fraction", tally[v].worst_flips},
                 {"worst_stretch_l2", tally[v].worst_l2}});
  return 0;
}

soupuv::bench::Suite reg("atlas-pipeline",
                         "atlas variants measured through the mapping job: continuity, flips, "
                         "stretch per sample (field lines cached across variants)",
                         run_atlas_pipeline);

}  // namespace
