// build_proxy on shapes with known answers (paper §5, Fig. 21): every proxy
// closed, manifold, outward, enclosing, without self-intersections, with the
// genus and component counts the shape dictates.
#include <gtest/gtest.h>

#include <atomic>
#include <memory>
#include <string>
#include <string_view>

#include "proxy_expect.h"
#include "soupuv/errors.h"
#include "soupuv/proxy/offset_policy.h"
#include "testing/shapes.h"

namespace soupuv::proxy {
namespace {

ProxyOptions relative(double fraction, int resolution = 0) {
  ProxyOptions o;
  o.offset_mode = OffsetMode::relative;
  o.offset = fraction;
  o.resolution = resolution;
  return o;
}

TEST(BuildProxy, SphereIsOneGenusZeroShell) {
  Soup soup = shapes::to_soup(shapes::sphere_with(1.0, 2000), 1e-3, 1);
  ProxyResult r = build_proxy(soup, relative(0.03));
  expect_valid_proxy(r, soup, 1);
  EXPECT_EQ(r.genus, 0);
  EXPECT_EQ(r.euler, 2);
  // The closed sphere's cavity is pruned from the narrow band, never built.
  EXPECT_EQ(r.inner_components, 0);
  EXPECT_GT(r.pruned_cells, 0u);
  // The proxy lies near d = o: its vertices' radius is about 1 + o.
  double o = r.offset;
  for (size_t i = 0; i < r.proxy.mesh.vertices.size(); i += 17)
    EXPECT_NEAR(norm(r.proxy.mesh.vertices[i]), 1 + o, 0.35 * o);
}

TEST(BuildProxy, TorusHasGenusOne) {
  Soup soup = shapes::to_soup(shapes::torus(1.0, 0.35, 48, 24), 1e-3, 2);
  ProxyResult r = build_proxy(soup, relative(0.02));
  expect_valid_proxy(r, soup, 1);
  EXPECT_EQ(r.genus, 1);
  EXPECT_EQ(r.euler, 0);
}

TEST(BuildProxy, CubeWithSharpEdges) {
  Soup soup = shapes::to_soup(shapes::cube(2.0, 4), 1e-3, 3);
  ProxyResult r = build_proxy(soup, relative(0.02));
  expect_valid_proxy(r, soup, 1);
  EXPECT_EQ(r.genus, 0);
}

// Two plates meeting along an edge at 30 degrees (Fig. 21): the narrow gap
// between them is the thin feature; the proxy must still be one closed shell.
TEST(BuildProxy, VOfTwoPlates) {
  TriMesh plate;
  int n = 8;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) plate.vertices.push_back({double(i) / n, double(j) / n - 0.5, 0});
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      int a = j * (n + 1) + i;
      plate.faces.push_back({a, a + 1, a + n + 2});
      plate.faces.push_back({a, a + n + 2, a + n + 1});
    }
  TriMesh tilted = plate;
  double angle = 30.0 * M_PI / 180;
  for (Vec3& v : tilted.vertices) v = {v.x * std::cos(angle), v.y, v.x * std::sin(angle)};
  Soup soup = shapes::merge(shapes::to_soup(plate), shapes::to_soup(tilted));
  ProxyResult r = build_proxy(soup, relative(0.02));
  expect_valid_proxy(r, soup, 1);
  EXPECT_EQ(r.genus, 0);
  EXPECT_EQ(r.inner_components, 0);
}

// A hollow shell: a closed sphere inside a closed sphere. The offset surface
// has an outer shell, the cavity between the spheres gives two inner ones.
TEST(BuildProxy, HollowShellDropsInnerComponents) {
  Soup soup = shapes::merge(shapes::to_soup(shapes::icosphere(1.0, 3)),
                            shapes::to_soup(shapes::icosphere(0.6, 3)));
  // The safety net: without pruning every shell is built, inner ones dropped.
  ProxyOptions unpruned = relative(0.02);
  unpruned.prune_cavities = false;
  ProxyResult r = build_proxy(soup, unpruned);
  expect_valid_proxy(r, soup, 1);
  EXPECT_GE(r.inner_components, 2);
  EXPECT_EQ(r.pruned_cells, 0u);
  // Only the outer shell is left: all vertices near radius 1 + o.
  for (const Vec3& v : r.proxy.mesh.vertices) EXPECT_GT(norm(v), 1.0);
  // With pruning the cavity is never refined: no inner shell to drop, and
  // about half the raw triangles for the same outer shell.
  ProxyResult pruned = build_proxy(soup, relative(0.02));
  expect_valid_proxy(pruned, soup, 1);
  EXPECT_GT(pruned.pruned_cells, 0u);
  EXPECT_EQ(pruned.inner_components, 0);
  EXPECT_LT(pruned.raw_triangles, r.raw_triangles * 2 / 3);
  for (const Vec3& v : pruned.proxy.mesh.vertices) EXPECT_GT(norm(v), 1.0);
}

TEST(BuildProxy, FarApartPartsGiveTwoOuterComponentsAndAWarning) {
  TriMesh a = shapes::icosphere(1.0, 2), b = shapes::cube(1.5, 2);
  shapes::translate(b, {4, 0, 0});
  Soup soup = shapes::merge(shapes::to_soup(a), shapes::to_soup(b));
  ProxyResult r = build_proxy(soup, relative(0.03));
  expect_valid_proxy(r, soup, 2);
  bool warned = false;
  for (const auto& w : r.warnings) warned |= w.find("outer components") != std::string::npos;
  EXPECT_TRUE(warned);
  ASSERT_EQ(r.proxy.face_component.size(), r.proxy.mesh.faces.size());
  EXPECT_EQ(*std::max_element(r.proxy.face_component.begin(), r.proxy.face_component.end()), 1);
}

TEST(BuildProxy, AutomaticPicksTheTightestSingleShell) {
  // Two spheres 0.3 apart: rungs whose 2o is below the gap give two shells,
  // so automatic must climb the ladder until they merge.
  TriMesh a = shapes::icosphere(1.0, 2), b = shapes::icosphere(1.0, 2);
  shapes::translate(b, {2.3, 0, 0});
  Soup soup = shapes::merge(shapes::to_soup(a), shapes::to_soup(b));
  ProxyOptions o;
  o.offset_mode = OffsetMode::automatic;
  o.max_resolution = 96;  // keeps the tight rungs cheap; still a valid level set
  ProxyResult r = build_proxy(soup, o);
  expect_valid_proxy(r, soup, 1);
  EXPECT_GT(r.offset, 0.14);
  ASSERT_GE(r.ladder_tried.size(), 2u);  // the tight rungs were tried and refused
  double diag = bounding_box(soup).diagonal();
  EXPECT_NEAR(r.offset, r.ladder_tried.back() * diag, 1e-12);
}

// The face budget: the estimate made right after marching cubes is close to
// what remeshing makes, an explicit offset over the budget is refused with a
// clear invalid_input error, and automatic moves on to a looser rung.
TEST(BuildProxy, FaceBudgetEstimateIsCloseToTheRemeshedCount) {
  Soup soup = shapes::to_soup(shapes::sphere_with(1.0, 2000), 1e-3, 1);
  for (double fraction : {0.01, 0.03}) {
    ProxyResult r = build_proxy(soup, relative(fraction));
    expect_valid_proxy(r, soup, 1);
    ASSERT_GT(r.estimated_triangles, 0);
    const double ratio = static_cast<double>(r.triangles) / r.estimated_triangles;
    EXPECT_GT(ratio, 0.7) << fraction;
    EXPECT_LT(ratio, 1.8) << fraction;
  }
}

TEST(BuildProxy, AnExplicitOffsetOverTheFaceBudgetIsRefused) {
  Soup soup = shapes::to_soup(shapes::sphere_with(1.0, 2000), 1e-3, 1);
  ProxyOptions o = relative(0.01);
  o.max_triangles = 2000;  // the 1 % proxy of a unit sphere is ~10x that
  try {
    build_proxy(soup, o);
    FAIL() << "not refused";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::invalid_input);
    EXPECT_NE(std::string_view(e.what()).find("budget of 2000"), std::string_view::npos) << e.what();
  }
  o.max_triangles = 0;  // no budget: built
  EXPECT_GT(build_proxy(soup, o).triangles, 2000u);
}

TEST(BuildProxy, AutomaticSkipsRungsOverTheFaceBudget) {
  Soup soup = shapes::to_soup(shapes::sphere_with(1.0, 2000), 1e-3, 1);
  ProxyOptions o;
  o.offset_mode = OffsetMode::automatic;
  o.ladder = {0.01, 0.03, 0.08};
  ProxyResult tight = build_proxy(soup, o);
  EXPECT_NEAR(tight.offset_fraction, 0.01, 1e-12);
  // A budget between the 3 % and 1 % proxies' sizes: the 1 % rung is skipped.
  o.max_triangles = static_cast<size_t>(0.5 * static_cast<double>(tight.triangles));
  ProxyResult r = build_proxy(soup, o);
  expect_valid_proxy(r, soup, 1);
  EXPECT_NEAR(r.offset_fraction, 0.03, 1e-12);
  EXPECT_LE(r.estimated_triangles, static_cast<double>(o.max_triangles));
  bool warned = false;
  for (const std::string& w : r.warnings) warned |= w.find("over the budget") != std::string::npos;
  EXPECT_TRUE(warned);
}

TEST(BuildProxy, RawLevelSetWithoutRemeshOrSmoothingIsValid) {
  Soup soup = shapes::to_soup(shapes::torus(1.0, 0.3, 32, 16), 1e-3, 4);
  ProxyOptions o = relative(0.03);
  o.remesh = false;
  o.smoothing_iterations = 0;
  ProxyResult r = build_proxy(soup, o);
  expect_valid_proxy(r, soup, 1);
  // The closed torus soup's cavity is pruned from the band: nothing removed.
  EXPECT_EQ(r.inner_components, 0);
  EXPECT_GT(r.pruned_cells, 0u);
  EXPECT_EQ(r.triangles, r.raw_triangles);
  EXPECT_EQ(r.genus, 1);
}

TEST(BuildProxy, ResolutionFollowsTheSamplingArgument) {
  // Table 1: cylinder r = 1, h = 2 (longest extent 2); offsets of 1, 2, 3, 5 %
  // of that extent need 200, 100, 67, 40 samples (cell = o / 2).
  ProxyOptions o;
  o.max_resolution = 4096;
  EXPECT_EQ(sampling_resolution(o, 2.0, 0.01 * 2), 200);
  EXPECT_EQ(sampling_resolution(o, 2.0, 0.02 * 2), 100);
  EXPECT_EQ(sampling_resolution(o, 2.0, 0.03 * 2), 67);
  EXPECT_EQ(sampling_resolution(o, 2.0, 0.05 * 2), 40);
  o.max_resolution = 150;
  EXPECT_EQ(sampling_resolution(o, 2.0, 0.01 * 2), 150);  // capped
  o.resolution = 77;
  EXPECT_EQ(sampling_resolution(o, 2.0, 0.01 * 2), 77);   // given
  // And build_proxy uses it.
  Soup soup = shapes::to_soup(shapes::cylinder(1.0, 2.0, 32, 4, 4));
  ProxyOptions b;
  b.offset_mode = OffsetMode::absolute;
  b.offset = 0.1 * 2;
  ProxyResult r = build_proxy(soup, b);
  EXPECT_EQ(r.resolution, 20);
  expect_valid_proxy(r, soup, 1);
}

TEST(BuildProxy, ErrorsAndCancel) {
  EXPECT_THROW(build_proxy(Soup{}, ProxyOptions{}), Error);
  Soup soup = shapes::to_soup(shapes::icosphere(1.0, 1));
  ProxyOptions bad = relative(-1);
  EXPECT_THROW(build_proxy(soup, bad), Error);
  Progress progress;
  progress.cancel();
  try {
    build_proxy(soup, relative(0.05), progress);
    FAIL() << "not canceled";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::canceled);
  }
}

// A cancel that arrives while marching cubes runs (inside its OpenMP region,
// where an escaping exception would terminate the process) comes out as
// Error{canceled}.
TEST(BuildProxy, CancelDuringMarchingCubesThrowsCanceled) {
  Soup soup = shapes::to_soup(shapes::icosphere(1.0, 3));
  std::shared_ptr<std::atomic<bool>> token;
  bool reached = false;
  Progress progress([&](std::string_view stage, double) {
    if (stage == "proxy: marching cubes") {
      reached = true;
      token->store(true);
    }
  });
  token = progress.cancel_token();
  try {
    build_proxy(soup, relative(0.01), progress);
    FAIL() << "not canceled";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::canceled);
  }
  EXPECT_TRUE(reached);
}

TEST(BuildProxy, DiagnosticsJsonCarriesTheChecks) {
  Soup soup = shapes::to_soup(shapes::icosphere(1.0, 2));
  ProxyResult r = build_proxy(soup, relative(0.05));
  nlohmann::json d = r.diagnostics();
  for (const char* key : {"closed", "manifold", "outward", "euler", "genus", "outer_components",
                          "inner_components", "encloses", "min_distance", "self_intersections",
                          "triangles", "seconds", "warnings"})
    EXPECT_TRUE(d.contains(key)) << key;
  EXPECT_EQ(d["triangles"].get<size_t>(), r.proxy.mesh.faces.size());
}

}  // namespace
}  // namespace soupuv::proxy
