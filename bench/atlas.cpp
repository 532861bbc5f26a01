// soupuv-bench atlas: build_atlas on closed meshes (spheres, tori, a genus-3
// surface, cube, cylinder, a CAD-like drilled block) at growing sizes; one
// JSON line per mesh with the issue-5 figures (charts, stretch, flips,
// overlap, utilisation, seconds, seam_length and seam_length_relative = seam
// length / sqrt(surface area)), then a summary with the worst values.
// Without --quick also 50k-100k meshes and the proxies (build_proxy with its
// defaults) of the shared sample soups spot, fandisk and suzanne.
// --quick: small sizes only (about a minute on a busy 2-core machine).
// --only=TEXT: just the meshes whose name contains TEXT.
#include <omp.h>

#include <algorithm>
#include <functional>
#include <iostream>

#include "bench_registry.h"
#include "soupuv/atlas/build_atlas.h"
#include "testing/test_meshes.h"
#include "soupuv/io/load.h"
#include "soupuv/proxy/proxy.h"
#include "testing/shapes.h"

namespace {

using namespace soupuv;

struct Case {
  std::string name;
  std::function<TriMesh()> make;
};

int run_atlas(const bench::Args& args) {
  std::vector<Case> cases = {
      {"sphere_5k", [] { return shapes::sphere_with(1.0, 5000); }},
      {"torus_5k", [] { return shapes::torus_with(1.0, 0.3, 5000); }},
      {"cube_1.7k", [] { return shapes::cube(2.0, 12); }},
      {"cylinder_2.6k", [] { return shapes::cylinder(0.5, 2.0, 48, 16, 6); }},
      {"genus3_12k", [] { return test_meshes::fused_tori(3, 12000); }},
      {"drilled_block_10k", [] { return test_meshes::drilled_block(10000); }},
  };
  if (!args.quick) {
    cases.push_back({"sphere_50k", [] { return shapes::sphere_with(1.0, 50000); }});
    cases.push_back({"torus_51k", [] { return shapes::torus_with(1.0, 0.3, 51200); }});
    cases.push_back({"genus3_40k", [] { return test_meshes::fused_tori(3, 40000); }});
    cases.push_back({"sphere_100k", [] { return shapes::sphere_with(1.0, 100000); }});
    cases.push_back({"torus_102k", [] { return shapes::torus_with(1.0, 0.3, 102400); }});
    cases.push_back({"genus3_100k", [] { return test_meshes::fused_tori(3, 100000); }});
    cases.push_back({"drilled_block_100k", [] { return test_meshes::drilled_block(100000); }});
    for (std::string name : {"spot", "fandisk", "suzanne"})
      cases.push_back({name + "_proxy", [name] {
                         io::Asset asset = io::load_file(std::string(SOUPUV_SHARED_DATA) +
                                                         "/soups/" + name + "-soup.glb");
                         return proxy::build_proxy(asset.soup, {}).proxy.mesh;
                       }});
  }
  // --only=TEXT keeps the meshes whose name contains TEXT; --normal-deviation=DEG
  // sets the segmentation budget (AtlasOptions::max_normal_deviation_deg; the
  // pipeline uses 70), --padding=PX the padding in texels, --merge turns
  // chart merging on (AtlasOptions::merge_charts), --merge-area=F and
  // --merge-fill=F set its limits (merge_max_area_fraction, merge_min_fill),
  // --merge-cone=DEG the merge normal cone, --relax turns seam relaxation on
  // (AtlasOptions::relax_seams; rows then carry seam_cost_before_relax).
  atlas::AtlasOptions options;
  for (const std::string& a : args.rest) {
    if (a.rfind("--normal-deviation=", 0) == 0) options.max_normal_deviation_deg = std::stod(a.substr(19));
    if (a.rfind("--padding=", 0) == 0) options.padding_px = std::stod(a.substr(10));
    if (a == "--merge") options.merge_charts = true;
    if (a.rfind("--merge-area=", 0) == 0) options.merge_max_area_fraction = std::stod(a.substr(13));
    if (a.rfind("--merge-fill=", 0) == 0) options.merge_min_fill = std::stod(a.substr(13));
    if (a.rfind("--merge-cone=", 0) == 0) options.merge_max_normal_deviation_deg = std::stod(a.substr(13));
    if (a == "--relax") options.relax_seams = true;
    if (a.rfind("--only=", 0) == 0) {
      std::string text = a.substr(7);
      std::erase_if(cases, [&](const Case& c) { return c.name.find(text) == std::string::npos; });
    }
  }
  double worst_l2 = 0, worst_util = 1, worst_seconds = 0;
  int total_flipped = 0;
  double worst_overlap = 0;
  for (const Case& c : cases) {
    TriMesh mesh;
    try {
      mesh = c.make();
    } catch (const std::exception& e) {
      bench::emit({{"suite", "atlas"}, {"mesh", c.name}, {"error", e.what()}});
      continue;
    }
    std::cerr << "atlas: " << c.name << " (" << mesh.faces.size() << " faces)\n";
    atlas::AtlasResult r = atlas::build_atlas(mesh, options, Progress::none());
    nlohmann::json row = {{"suite", "atlas"},
                          {"mesh", c.name},
                          {"triangles", mesh.faces.size()},
                          {"threads", bench::threads()},
                          {"peak_rss_mb", bench::peak_rss_mb()}};
    row.update(r.diagnostics());
    bench::emit(row);
    worst_l2 = std::max(worst_l2, r.stats.stretch_l2);
    worst_util = std::min(worst_util, r.stats.utilization);
    worst_seconds = std::max(worst_seconds, r.stats.seconds);
    total_flipped += r.stats.flipped;
    worst_overlap = std::max(worst_overlap, r.stats.overlap);
  }
  bench::emit({{"suite", "atlas"},
               {"kind", "summary"},
               {"meshes", cases.size()},
               {"worst_stretch_l2", worst_l2},
               {"worst_utilization", worst_util},
               {"flipped", total_flipped},
               {"worst_overlap", worst_overlap},
               {"worst_seconds", worst_seconds}});
  return 0;
}

soupuv::bench::Suite reg("atlas", "proxy atlas: charts, stretch, flips, overlap, utilisation, seconds",
                         run_atlas);

}  // namespace
