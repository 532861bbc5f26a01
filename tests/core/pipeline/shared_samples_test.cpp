// The shared noisy soups end to end (paper §10 protocol), with continuity
// against their welded originals: the figures the targets name, as
// floors at what the pipeline reaches with the UV repair on (session 4, with
// the repair's untangling start; offset 0.03): suzanne flipped 1.24 % (9.7
// before the repair), L2 3.58 (5.85), continuity 0.861 (0.863); spot 0.0 %
// (0.68), L2 1.15 (3.35), continuity 0.926 (0.927) — spot meets the issue's
// 0.5 % / 1.3, suzanne does not, neither reaches 0.95 continuity. The
// repair must improve the stretch and flip figures of the unrepaired map it
// reports beside them. All samples: `soupuv-bench pipeline --only samples`.
#include <gtest/gtest.h>

#include <string>

#include "pipeline_support.h"
#include "soupuv/io/load.h"

using namespace soupuv;
using namespace soupuv::testing;

namespace {

struct Sample {
  const char* name;
  double max_flipped, max_stretch_l2, min_continuity;
};

nlohmann::json map_shared(const std::string& name) {
  const std::string dir = std::string(SOUPUV_SHARED_DATA) + "/soups/";
  const Soup soup = io::load_file(dir + name + "-soup.glb").soup;
  const Soup original = io::load_file(dir + name + "-soup.original.glb").soup;
  MapOptions o = fast_options();
  o.candidates = map_candidates();  // the product: the search on these coarse soups
  o.original = &original;
  o.uv_repair = true;
  return run_map(soup, o).diagnostics;
}

// A real glTF sample (continuity by welding: no original).
nlohmann::json map_gltf(const std::string& path) {
  io::LoadOptions lo;
  lo.allow_external_uris = true;
  const Soup soup = io::load_file(std::string(SOUPUV_SHARED_DATA) + "/gltf/" + path, lo).soup;
  MapOptions o = fast_options();
  o.candidates = map_candidates();
  o.uv_repair = true;
  return run_map(soup, o).diagnostics;
}

void check(const Sample& s, const nlohmann::json& d) {
  const auto& uv = d["uv"];
  const auto& before = d["uv_repair"]["before"];
  std::cout << s.name << ": " << uv.dump() << "\n  before repair: " << before.dump() << "\n";
  EXPECT_EQ(uv["coverage"].get<double>(), 1.0);
  EXPECT_LE(uv["flipped_fraction"].get<double>(), s.max_flipped);
  EXPECT_LE(uv["stretch_l2"].get<double>(), s.max_stretch_l2);
  EXPECT_GE(uv["continuity"].get<double>(), s.min_continuity);
  // The repair is only worth its place if it helps where it acts.
  EXPECT_GT(uv["repaired_vertices"].get<size_t>(), 0u);
  EXPECT_LT(uv["stretch_l2"].get<double>(), before["stretch_l2"].get<double>());
  EXPECT_LE(uv["flipped_fraction"].get<double>(), before["flipped_fraction"].get<double>());
  // The island relaxation (transfer/island_relax.h) never adds overlap.
  const auto& ir = d["island_relax"];
  EXPECT_TRUE(ir["ran"].get<bool>());
  EXPECT_LE(ir["overlap_texels_after"].get<long>(), ir["overlap_texels_before"].get<long>());
  EXPECT_LE(ir["stretch_l2_after"].get<double>(), ir["stretch_l2_before"].get<double>());
}

void check(const Sample& s) { check(s, map_shared(s.name)); }

}  // namespace

// Floors under session 5's figures (edge weld + island start + split
// corners; loaded machine): suzanne 0 % / 1.10 / 0.912, spot 0 % / 1.19 /
// 0.959. Suzanne was 1.14 % / 3.47 / 0.906 with the corner weld.
// Session 6 (seeds welded by edges, the re-weld, strict retry 1.05, the
// repair's growth while bad; the atlas's segmentation budgets), measured
// here, continuity / flipped / L2: suzanne 0.9505 / 0 % / 1.11, spot 0.972 /
// 0 % / 1.11, teapot 0.955 / 0.06 % / 1.10. Floors a little under them
// (one suzanne pair is 0.0007 of continuity); teapot's is the 0.95.
// Session 7, the candidate search (map_candidates(), chosen by welded
// continuity within 0.5 % / 1.3), `soupuv-bench pipeline --only samples`
// with atlas's 7874d77 list (default, c130, nc110, nc120d, nc150d), loaded
// machine: suzanne 0.9686 / 0 % / 1.116 (nc110), spot 0.9834 / 0 % / 1.199
// (nc120d), teapot 0.9644 / 0.06 % / 1.176 (nc150d). The L2 floors are the
// issue's 1.3, which the search itself enforces.
TEST(SharedSamples, Suzanne) { check({"suzanne", 0.005, 1.3, 0.965}); }

TEST(SharedSamples, Spot) { check({"spot", 0.005, 1.3, 0.978}); }

TEST(SharedSamples, Teapot) { check({"teapot", 0.005, 1.3, 0.96}); }

// Fox (576 triangles, continuity by welding), session 8: the island
// relaxation brings atlas's o37d candidate (0.954 continuity, L2 1.47 as
// landed) under the 1.3 bound (1.29), so the search takes it: 0.9537 / 0 %
// / 1.292 (`soupuv-bench pipeline --only Fox`, loaded machine; session 7:
// 0.9236 with nc120d). The floor is the 0.95.
TEST(SharedSamples, Fox) { check({"Fox", 0.005, 1.3, 0.95}, map_gltf("Fox/Fox.gltf")); }
