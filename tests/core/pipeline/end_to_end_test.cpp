// End to end on small shapes: the targets as assertions (see
// pipeline_support.h for the continuity floor), the box baseline beside it.
#include <gtest/gtest.h>

#include "pipeline_support.h"
#include "soupuv/errors.h"

using namespace soupuv;
using namespace soupuv::testing;

TEST(EndToEnd, NoisySphereAndTheBoxBaseline) {
  TriMesh mesh = shapes::sphere_with(1.0, 800);
  Soup soup = shapes::to_soup(mesh, 1e-3, 1);
  Soup original = welded(mesh);
  MapOptions o = fast_options();
  o.original = &original;
  MapResult field = run_map(soup, o);
  const auto& d = field.diagnostics;
  EXPECT_EQ(field.corner_uvs.size(), 3 * soup.triangles.size());
  EXPECT_EQ(d["soup"]["triangles"], soup.triangles.size());
  expect_targets(d);
  EXPECT_TRUE(d["proxy"]["closed"].get<bool>());
  EXPECT_EQ(d["proxy"]["outer_components"], 1);
  EXPECT_GE(d["trace"]["hit_fraction"].get<double>(), 0.99);
  for (const char* stage : {"charge", "trace", "proxy", "atlas", "transfer"})
    EXPECT_GE(d["stages"][stage]["seconds"].get<double>(), 0.0) << stage;

  o.method = MapMethod::box;
  MapResult box = run_map(soup, o);
  for (const char* key : {"coverage", "flipped_fraction", "stretch_l2", "continuity", "islands"})
    EXPECT_TRUE(box.diagnostics["uv"].contains(key)) << key;
  // No "field beats box" assertion here: on a sphere the box projection is
  // nearly ideal (6 islands) while the proxy atlas has ~20 charts; the
  // comparison that matters is on the shared soups, in soupuv-bench pipeline.
  EXPECT_EQ(box.diagnostics["method"], "box");
}

TEST(EndToEnd, VPlatesGetOneSidePerPlate) {
  TriMesh mesh = v_plates(8, 25);
  Soup soup = shapes::to_soup(mesh, 1e-3, 1);
  Soup original = welded(mesh);
  MapOptions o = fast_options();
  o.original = &original;
  MapResult r = run_map(soup, o);
  EXPECT_EQ(r.diagnostics["uv"]["coverage"].get<double>(), 1.0);
  EXPECT_EQ(r.diagnostics["orient"]["mixed_side_triangles_after"], 0) << r.diagnostics["orient"].dump();
  EXPECT_EQ(r.diagnostics["orient"]["components"], 1);
}

TEST(EndToEnd, CancelThrowsCanceled) {
  Soup soup = shapes::to_soup(shapes::sphere_with(1.0, 200), 1e-3, 1);
  Progress p;
  p.cancel();
  try {
    run_map(soup, fast_options(), p);
    FAIL() << "no exception";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::canceled);
  }
}

TEST(EndToEnd, EmptySoupIsNoTriangles) {
  Soup empty;
  try {
    run_map(empty, fast_options());
    FAIL() << "no exception";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::no_triangles);
  }
}
