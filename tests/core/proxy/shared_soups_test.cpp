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
}

INSTANTIATE_TEST_SUITE_P(Soups, SharedSoup,
                         ::testing::Values("suzanne", "spot", "teapot", "fandisk", "stanford-bunny"));

}  // namespace
}  // namespace soupuv::proxy
