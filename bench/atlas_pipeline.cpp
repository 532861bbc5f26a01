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
//                        Keys: angle (max_normal_deviation_deg), alt_angle
//                        (appends to alternative_normal_deviations_deg;
//                        repeatable), no_alt_angles (clears them), stretch
//                        (max_stretch), merge (0/1), merge_crease,
//                        merge_area, merge_fill, merge_cone
//                        (merge_max_normal_deviation_deg), merge_stretch
//                        (merge_max_stretch), merge_sweeps
//                        (merge_stretch_sweeps), pack_splits,
//                        split_below, relax (0/1: seam relaxation),
//                        relax_band, relax_stretch, relax_narrow, soup_weights (0/1: seam weights from
//                        the soup's edge density, with relax),
//                        offset (proxy offset, fraction of the diagonal;
//                        default: auto), proxy_edge (proxy remeshing edge
//                        length, fraction of the diagonal; default: the
//                        offset).
//   --quick              suzanne and Fox, the pipeline's atlas only.
//   --dump-uvs DIR       also write DIR/MESH-VARIANT.uv.txt: per soup triangle
//                        its corners' x y z u v (to draw the seams).
//   --charts             also, per (sample, variant), the stretch tail and one
//                        line per chart: where the soup's stretch comes from
//                        (soup area landed on the chart, the soup's L2 there,
//                        the proxy chart's own L2, and that L2 weighted by
//                        the soup area landed per proxy face).
//
// One JSON line per (sample, variant) with the uv figures, the atlas's
// charts / utilisation / seam length and the discontinuity causes; then one
// summary line per variant (mean and worst continuity, worst flips).
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <fstream>
#include <iostream>
#include <sstream>

#include "bench_registry.h"
#include "soupuv/cache/store.h"
#include "soupuv/errors.h"
#include "soupuv/io/load.h"
#include "soupuv/pipeline.h"
#include "soupuv/quality/uv_metrics.h"
#include "soupuv/geometry/triangle_stretch.h"

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

// One "K=V" of a variant spec into the atlas options or the proxy offset;
// false for a key it does not know.
bool apply_atlas_key(const std::string& key, double value, Variant& v) {
  atlas::AtlasOptions& a = v.atlas;
  if (key == "angle") a.max_normal_deviation_deg = value;
  else if (key == "alt_angle") a.alternative_normal_deviations_deg.push_back(value);
  else if (key == "no_alt_angles") a.alternative_normal_deviations_deg.clear();
  else if (key == "stretch") a.max_stretch = value;
  else if (key == "merge") a.merge_charts = value != 0;
  else if (key == "merge_crease") a.merge_crease_deg = value;
  else if (key == "merge_cone") a.merge_max_normal_deviation_deg = value;
  else if (key == "merge_area") a.merge_max_area_fraction = value;
  else if (key == "merge_fill") a.merge_min_fill = value;
  else if (key == "merge_stretch") a.merge_max_stretch = value;
  else if (key == "merge_sweeps") a.merge_stretch_sweeps = int(value);
  else if (key == "pack_splits") a.packing_split_rounds = int(value);
  else if (key == "split_below") a.packing_split_below = value;
  else if (key == "relax") a.relax_seams = value != 0;
  else if (key == "relax_band") a.relax_band = value;
  else if (key == "relax_stretch") a.relax_max_stretch_increase = value;
  else if (key == "relax_narrow") a.relax_narrowings = int(value);
  else if (key == "soup_weights") a.soup_seam_weights = value != 0;
  else if (key == "offset") v.offset = value;
  else if (key == "proxy_edge") v.proxy_edge = value;
  else return false;
  return true;
}

// "NAME:K=V,K=V" -> a variant of the pipeline's atlas (the keys above).
// Throws Error{invalid_input} on a missing name, an unknown key or a value
// that is not a number.
Variant parse_variant(const std::string& text) {
  Variant v;
  const size_t colon = text.find(':');
  v.name = text.substr(0, colon);
  if (v.name.empty()) throw Error(ErrorCode::invalid_input, "a variant needs a name: " + text);
  if (colon == std::string::npos) return v;
  std::stringstream list(text.substr(colon + 1));
  for (std::string item; std::getline(list, item, ',');) {
    const size_t eq = item.find('=');
    if (eq == std::string::npos) throw Error(ErrorCode::invalid_input, "variant item without '=': " + item);
    double value = 0;
    try {
      size_t used = 0;
      value = std::stod(item.substr(eq + 1), &used);
      if (used != item.size() - eq - 1) throw std::invalid_argument("trailing text");
    } catch (const std::exception&) {
      throw Error(ErrorCode::invalid_input, "variant item needs a number: " + item);
    }
    if (!apply_atlas_key(item.substr(0, eq), value, v))
      throw Error(ErrorCode::invalid_input, "unknown variant key: " + item.substr(0, eq));
  }
  return v;
}

// Per chart of the debug atlas: which soup triangles landed on it (by the UV
// centroid, brute force over the proxy's UV triangles: benches only) and the
// stretch figures at the atlas's texel scale.
void emit_chart_rows(const std::string& mesh, const std::string& variant, const Soup& soup,
                     const MapResult& r) {
  const atlas::Atlas& at = r.debug.atlas;
  const TriMesh& proxy = r.debug.proxy.mesh;
  const double scale = at.uv_per_length;
  const int nc = at.chart_count;
  std::vector<double> soup_area(nc, 0), soup_sq(nc, 0), proxy_area(nc, 0), proxy_sq(nc, 0);
  std::vector<double> face_soup_area(proxy.faces.size(), 0), face_sq(proxy.faces.size(), 0);
  for (size_t f = 0; f < proxy.faces.size(); ++f) {
    const auto& fv = proxy.faces[f];
    const Vec3 p0 = proxy.vertices[fv[0]], p1 = proxy.vertices[fv[1]], p2 = proxy.vertices[fv[2]];
    geometry::SanderStretch st;
    const double a = 0.5 * norm(cross(p1 - p0, p2 - p0));
    if (!geometry::sander_stretch(p0, p1, p2, at.face_uvs[f], st)) continue;
    face_sq[f] = 0.5 * (st.big * st.big + st.small * st.small) * scale * scale;
    proxy_area[at.face_chart[f]] += a;
    proxy_sq[at.face_chart[f]] += a * face_sq[f];
  }
  auto inside = [](Vec2 p, const std::array<Vec2, 3>& t) {
    const double d0 = cross(t[1] - t[0], p - t[0]), d1 = cross(t[2] - t[1], p - t[1]),
                 d2 = cross(t[0] - t[2], p - t[2]);
    return (d0 >= 0 && d1 >= 0 && d2 >= 0) || (d0 <= 0 && d1 <= 0 && d2 <= 0);
  };
  for (size_t t = 0; t < soup.triangles.size(); ++t) {
    const std::array<Vec2, 3> uv = {r.corner_uvs[3 * t], r.corner_uvs[3 * t + 1], r.corner_uvs[3 * t + 2]};
    const Vec2 c = (uv[0] + uv[1] + uv[2]) * (1.0 / 3.0);
    int face = -1;
    for (size_t f = 0; f < proxy.faces.size() && face < 0; ++f)
      if (inside(c, at.face_uvs[f])) face = static_cast<int>(f);
    if (face < 0) continue;
    const double a = triangle_area(soup, t);
    geometry::SanderStretch st;
    if (!(a > 0) || !geometry::sander_stretch(soup.corner(t, 0), soup.corner(t, 1), soup.corner(t, 2), uv, st))
      continue;
    soup_area[at.face_chart[face]] += a;
    soup_sq[at.face_chart[face]] += a * 0.5 * (st.big * st.big + st.small * st.small) * scale * scale;
    face_soup_area[face] += a;
  }
  // The proxy chart's stretch weighted by the soup area that landed on each
  // face: what the soup would wear if the field map soup -> proxy were a
  // similarity. Far below soup_l2 means the stretch comes from the field map
  // (lines that diverge or converge), not from the chart's flattening.
  std::vector<double> weighted_sq(nc, 0);
  for (size_t f = 0; f < proxy.faces.size(); ++f) weighted_sq[at.face_chart[f]] += face_soup_area[f] * face_sq[f];
  for (int c = 0; c < nc; ++c)
    bench::emit({{"suite", "atlas-pipeline"},
                 {"kind", "chart"},
                 {"mesh", mesh},
                 {"variant", variant},
                 {"chart", c},
                 {"soup_area", soup_area[c]},
                 {"soup_l2", soup_area[c] > 0 ? std::sqrt(soup_sq[c] / soup_area[c]) : 0},
                 {"proxy_l2_soup_weighted", soup_area[c] > 0 ? std::sqrt(weighted_sq[c] / soup_area[c]) : 0},
                 {"proxy_area", proxy_area[c]},
                 {"proxy_l2", proxy_area[c] > 0 ? std::sqrt(proxy_sq[c] / proxy_area[c]) : 0}});
}

double cpu_seconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

// One line per soup triangle: its three corners' x y z u v, to look at where
// the seams run (scripts outside the repo draw them).
void dump_uvs(const std::string& path, const Soup& soup, const MapResult& r) {
  std::ofstream out(path);
  for (size_t t = 0; t < soup.triangles.size(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const Vec3 p = soup.corner(t, k);
      const Vec2 uv = r.corner_uvs[3 * t + k];
      out << p.x << ' ' << p.y << ' ' << p.z << ' ' << uv.x << ' ' << uv.y << (k < 2 ? ' ' : '\n');
    }
  }
}

int run_atlas_pipeline(const bench::Args& args) {
  std::vector<std::string> only;
  std::vector<Variant> variants;
  std::string dump_dir;
  const bool charts = std::find(args.rest.begin(), args.rest.end(), "--charts") != args.rest.end();
  for (size_t i = 0; i + 1 < args.rest.size(); ++i) {
    if (args.rest[i] == "--only") {
      std::stringstream list(args.rest[i + 1]);
      for (std::string n; std::getline(list, n, ',');) only.push_back(n);
    }
    if (args.rest[i] == "--variant") variants.push_back(parse_variant(args.rest[i + 1]));
    if (args.rest[i] == "--dump-uvs") dump_dir = args.rest[i + 1];
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
      o.keep_debug = charts;
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
      if (!dump_dir.empty()) dump_uvs(dump_dir + "/" + s.name + "-" + variants[v].name + ".uv.txt", soup, r);
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
                            {"proxy_min_distance_ratio", d["proxy"]["min_distance_ratio"]},
                            {"proxy_resolution", d["proxy"]["resolution"]},
                            {"proxy_genus", d["proxy"]["genus"]},
                            {"proxy_seconds", d["proxy"]["seconds"]},
                            {"proxy_offset_fraction", d["proxy"]["offset_fraction"]},
                            {"charts", a["charts"]},
                            {"utilization", a["utilization"]},
                            {"seam_length_relative", a["seam_length_relative"]},
                            {"seam_cost_before_relax", a["seam_cost_before_relax"]},
                            {"seam_cost", a["seam_cost"]},
                            {"relaxed_pairs", a["relaxed_pairs"]},
                            {"segment_angle_deg", a["segment_angle_deg"]},
                            {"atlas_seconds", a["seconds"]},
                            {"atlas_seconds_parts",
                             {{"segment", a["seconds_segment"]}, {"parameterize", a["seconds_parameterize"]},
                              {"merge", a["seconds_merge"]}, {"pack", a["seconds_pack"]}}},
                            {"seconds", seconds},
                            {"cpu_seconds", cpu_seconds() - c0},
                            {"field_cached", d["cache"]["hits"].get<double>() > 0}};
      row["causes"] = uv["causes"];
      bench::emit(row);
      if (charts) {
        bench::emit({{"suite", "atlas-pipeline"}, {"kind", "stretch_tail"}, {"mesh", s.name},
                     {"variant", variants[v].name}, {"stretch_tail", uv["stretch_tail"]}});
        emit_chart_rows(s.name, variants[v].name, soup, r);
      }
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
