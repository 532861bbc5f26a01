// The monopole field does not depend on the proxy (§9): a re-run with a new
// offset must reuse the cached charges and field lines.
#include <gtest/gtest.h>

#include <filesystem>

#include "pipeline_support.h"
#include "pipeline/weld_cache.h"
#include "soupuv/cache/store.h"
#include "soupuv/geometry/weld.h"

using namespace soupuv;
using namespace soupuv::testing;

TEST(CacheRerun, NewOffsetReusesChargesAndLines) {
  TriMesh mesh = shapes::sphere_with(1.0, 500);
  Soup soup = shapes::to_soup(mesh, 1e-3, 3);
  Soup original = welded(mesh);
  cache::Store store;  // its own, so the first run is a miss
  MapOptions o = fast_options();
  o.cache = &store;
  o.original = &original;
  o.proxy.offset_mode = proxy::OffsetMode::relative;
  o.proxy.offset = 0.03;
  MapResult first = run_map(soup, o);
  EXPECT_EQ(first.diagnostics["cache"]["hits"], 0);
  EXPECT_FALSE(first.diagnostics["stages"]["trace"]["cached"].get<bool>());

  o.proxy.offset = 0.05;
  MapResult second = run_map(soup, o);
  EXPECT_EQ(second.diagnostics["cache"]["hits"], 2);
  EXPECT_TRUE(second.diagnostics["stages"]["trace"]["cached"].get<bool>());
  EXPECT_NE(first.diagnostics["proxy"]["offset"], second.diagnostics["proxy"]["offset"]);
  EXPECT_EQ(second.diagnostics["uv"]["coverage"].get<double>(), 1.0);
  EXPECT_LT(second.diagnostics["stages"]["trace"]["seconds"].get<double>(),
            0.5 * first.diagnostics["stages"]["trace"]["seconds"].get<double>());
}

TEST(CacheRerun, DirectoryStoreServesANewProcessStore) {
  namespace fs = std::filesystem;
  fs::path dir = fs::path(SOUPUV_BINARY_DIR) / "test-tmp" / "pipeline_cache_dir";
  fs::remove_all(dir);
  Soup soup = shapes::to_soup(shapes::sphere_with(1.0, 200), 1e-3, 2);
  MapOptions o = fast_options();
  {
    cache::Store store({.memory_bytes = 1 << 26, .directory = dir.string()});
    o.cache = &store;
    run_map(soup, o);
  }
  cache::Store fresh({.memory_bytes = 1 << 26, .directory = dir.string()});
  o.cache = &fresh;
  MapResult again = run_map(soup, o);
  EXPECT_TRUE(again.diagnostics["stages"]["trace"]["cached"].get<bool>());
  EXPECT_GE(fresh.stats().disk_hits, 1u);
}

// The soup's welds depend on the soup alone: a re-run with a new offset
// reads them from the cache (pipeline/weld_cache.h), and what it reads is
// the weld itself.
TEST(CacheRerun, NewOffsetReusesTheSoupWelds) {
  Soup soup = shapes::to_soup(shapes::sphere_with(1.0, 300), 1e-3, 4);
  cache::Store store;
  MapOptions o = fast_options();
  o.cache = &store;
  MapResult first = run_map(soup, o);
  EXPECT_FALSE(first.diagnostics["stages"]["weld"]["cached"].get<bool>());
  o.proxy.offset = 0.05;
  MapResult second = run_map(soup, o);
  EXPECT_TRUE(second.diagnostics["stages"]["weld"]["cached"].get<bool>());

  const std::string hash = geometry_hash(soup);
  const double tol = 4e-3 * bounding_box(soup).diagonal();
  const geometry::Weld direct = geometry::weld_by_edges(soup, tol, 1.05);
  const std::string recipe = pipeline::weld_recipe("edges", {tol, 1.05});
  bool hit = true;
  cache::Store fresh;
  auto compute = [&] { return geometry::weld_by_edges(soup, tol, 1.05); };
  const geometry::Weld missed = pipeline::cached_weld(&fresh, hash, recipe, compute, hit);
  EXPECT_FALSE(hit);
  const geometry::Weld read = pipeline::cached_weld(&fresh, hash, recipe, compute, hit);
  EXPECT_TRUE(hit);
  EXPECT_EQ(read.vertex_count, direct.vertex_count);
  EXPECT_TRUE(read.corner_vertex == direct.corner_vertex);
  EXPECT_TRUE(missed.corner_vertex == direct.corner_vertex);
  // Another recipe is another key.
  pipeline::cached_weld(&fresh, hash, pipeline::weld_recipe("edges", {tol, 1.2}), compute, hit);
  EXPECT_FALSE(hit);
}
