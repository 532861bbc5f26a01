// build_proxy on the noisy soups of ../shared/data/soups (paper §10 protocol),
// loaded through io::load_file: automatic offset, moderate resolution so the
// suite stays fast. Every proxy closed, manifold, outward, one outer shell,
// enclosing every soup vertex.
#include <gtest/gtest.h>

#include <filesystem>

#include "proxy_expect.h"
#include "soupuv/io/load.h"

namespace soupuv::proxy {
namespace {

class SharedSoup : public ::testing::TestWithParam<const char*> {};

TEST_P(SharedSoup, AutomaticProxyIsOneEnclosingShell) {
  std::string path = std::string(SOUPUV_SHARED_DATA) + "/soups/" + GetParam() + "-soup.glb";
  ASSERT_TRUE(std::filesystem::exists(path)) << path;
  Soup soup = io::load_file(path).soup;
  ASSERT_GT(soup.triangles.size(), 0u);
  ProxyOptions o;  // automatic offset
  o.max_resolution = 96;
  ProxyResult r = build_proxy(soup, o);
  expect_valid_proxy(r, soup, 1);
  // The finished proxy itself passed (no fallback to the unremeshed level
  // set), lifted close to d = o, and no bigger than atlas and transfer need.
  for (const auto& w : r.warnings) EXPECT_EQ(w.find("failed a check"), std::string::npos) << w;
  EXPECT_GE(r.min_distance_ratio, 0.7);
  EXPECT_LT(r.triangles, 60000u);
}

INSTANTIATE_TEST_SUITE_P(Soups, SharedSoup,
                         ::testing::Values("suzanne", "spot", "teapot", "fandisk", "stanford-bunny"));

}  // namespace
}  // namespace soupuv::proxy

namespace soupuv::proxy {
namespace {

// The other sample meshes: closed, open (a single plane), skinned, Draco.
class SharedMesh : public ::testing::TestWithParam<const char*> {};

TEST_P(SharedMesh, AutomaticProxyIsOneEnclosingShell) {
  std::string path = std::string(SOUPUV_SHARED_DATA) + "/" + GetParam();
  ASSERT_TRUE(std::filesystem::exists(path)) << path;
  io::LoadOptions load;
  load.allow_external_uris = true;
  load.base_dir = std::filesystem::path(path).parent_path().string();
  Soup soup = io::load_file(path, load).soup;
  ProxyOptions o;
  o.max_resolution = 64;
  ProxyResult r = build_proxy(soup, o);
  expect_valid_proxy(r, soup, 1);
}

INSTANTIATE_TEST_SUITE_P(Meshes, SharedMesh,
                         ::testing::Values("gltf/Box.glb", "gltf/Duck.glb", "gltf/CesiumMan.glb",
                                           "gltf/TwoSidedPlane/TwoSidedPlane.gltf",
                                           "drc/bunny_gltf.drc"));

}  // namespace
}  // namespace soupuv::proxy
