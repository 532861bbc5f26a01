// geometry::weld_by_edges on the shared teapot soup against its original's adjacency
// (here because this suite links the loader).
#include <gtest/gtest.h>

#include <algorithm>
#include <set>

#include "soupuv/io/load.h"
#include "adjacent_pair_set.h"
#include "soupuv/quality/uv_metrics.h"
#include "soupuv/geometry/weld.h"
#include "shared_data.h"

using namespace soupuv;
using namespace soupuv::quality;
using soupuv::testing::PairSet;
using soupuv::testing::pair_set;

// The shared teapot soup: its rim rows are closer than the noise, where
// welding corners nearest-first joins distinct vertices. Matching edges
// joins far fewer (measured 430 -> 134 false neighbour pairs).
TEST(EdgeWeld, TeapotRimHasFewerFalseNeighboursThanCornerWelding) {
  const std::string dir = soupuv_test::shared_data_dir();
  const io::Asset soup = io::load_file(dir + "/soups/teapot-soup.glb");
  const io::Asset original = io::load_file(dir + "/soups/teapot-soup.original.glb");
  const size_t n = soup.soup.triangles.size();
  const double diag = bounding_box(soup.soup).diagonal();
  const PairSet truth = pair_set(metric_adjacency(soup.soup, &original.soup, 0));
  auto false_pairs = [&](const geometry::Weld& w) {
    size_t wrong = 0;
    for (const auto& p : pair_set(geometry::edge_adjacency(w, n))) wrong += !truth.count(p);
    return wrong;
  };
  auto missed_pairs = [&](const geometry::Weld& w) {
    const PairSet got = pair_set(geometry::edge_adjacency(w, n));
    size_t missed = 0;
    for (const auto& p : truth) missed += !got.count(p);
    return missed;
  };
  const geometry::Weld corners = geometry::weld_corners(soup.soup, 2e-3 * diag, 1.0);
  const geometry::Weld edges = geometry::weld_by_edges(soup.soup, 4e-3 * diag);
  EXPECT_LT(false_pairs(edges), 200u);
  EXPECT_GT(false_pairs(corners), 2 * false_pairs(edges));
  EXPECT_LT(missed_pairs(edges), missed_pairs(corners));
  // Refusing ambiguous edges trades false pairs for missed ones.
  const geometry::Weld strict = geometry::weld_by_edges(soup.soup, 4e-3 * diag, 2.0);
  EXPECT_LT(false_pairs(strict), 30u);
  EXPECT_GT(missed_pairs(strict), missed_pairs(edges));
  // Matching only neighbours that run back (the soup's winding is
  // consistent) joins fewer wrong pairs without missing more right ones
  // (measured: false 134 -> 113, missed 203 -> 169).
  const geometry::Weld consistent = geometry::weld_by_edges(soup.soup, 4e-3 * diag, 1.0, false);
  EXPECT_LT(false_pairs(consistent), false_pairs(edges));
  EXPECT_LE(missed_pairs(consistent), missed_pairs(edges));
}

// The shared lines' seed weld (field_branch.h): edges first, then distance on
// top (geometry::extend_weld, edge fraction 0.5 as run_map asks). Counted on the
// original's neighbour pairs whose shared corners would start different
// lines (measured: corner weld 448, edge weld 269, both 243 of 9,400; 225
// with edge fraction 1), and never two corners of one triangle in a group.
TEST(EdgeWeld, TeapotSeedWeldSplitsFewerNeighboursThanEitherWeld) {
  const std::string dir = soupuv_test::shared_data_dir();
  const io::Asset soup = io::load_file(dir + "/soups/teapot-soup.glb");
  const io::Asset original = io::load_file(dir + "/soups/teapot-soup.original.glb");
  const size_t n = soup.soup.triangles.size();
  const double diag = bounding_box(soup.soup).diagonal();
  const auto truth = metric_adjacency(soup.soup, &original.soup, 0);
  auto split_pairs = [&](const geometry::Weld& w) {
    size_t split = 0;
    for (const auto& p : truth)
      split += w.corner_vertex[3 * p.a + p.a_corner[0]] != w.corner_vertex[3 * p.b + p.b_corner[0]] ||
               w.corner_vertex[3 * p.a + p.a_corner[1]] != w.corner_vertex[3 * p.b + p.b_corner[1]];
    return split;
  };
  const geometry::Weld corners = geometry::weld_corners(soup.soup, 2e-3 * diag, 1.0);
  const geometry::Weld edges = geometry::weld_by_edges(soup.soup, 4e-3 * diag);
  const geometry::Weld seeds = geometry::extend_weld(soup.soup, edges, 2e-3 * diag, 0.5);
  EXPECT_LT(split_pairs(seeds), split_pairs(edges));
  EXPECT_LT(split_pairs(edges), split_pairs(corners));
  EXPECT_LT(split_pairs(seeds), 250u);
  for (size_t t = 0; t < n; ++t) {
    const uint32_t* v = &seeds.corner_vertex[3 * t];
    EXPECT_TRUE(v[0] != v[1] && v[1] != v[2] && v[0] != v[2]) << t;
  }
}
