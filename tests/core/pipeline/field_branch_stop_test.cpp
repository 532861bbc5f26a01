// The field branch's stop box (field_branch.h: proxy_reach, stop_box_for):
// lines end once they are surely past every proxy within the reach, they are
// the same lines as far-traced ones up to there, and the cache serves every
// offset within the reach and re-traces for a farther one.
#include <gtest/gtest.h>

#include "pipeline/field_branch.h"
#include "pipeline_support.h"

using namespace soupuv;

namespace {

bool inside(const Box3& b, Vec3 p) {
  return p.x >= b.lo.x && p.y >= b.lo.y && p.z >= b.lo.z && p.x <= b.hi.x && p.y <= b.hi.y &&
         p.z <= b.hi.z;
}

pipeline::FieldBranchOptions branch_options() {
  pipeline::FieldBranchOptions o;
  o.threads = 2;
  o.weld_tolerance = 2e-3;
  o.weld_edge_fraction = 1.0;
  return o;
}

}  // namespace

TEST(FieldBranchStop, ReachIsTheLadderTopOrAFartherOffset) {
  const Soup soup = shapes::to_soup(shapes::cube(2.0, 2), 0, 1);
  const double diag = bounding_box(soup).diagonal();
  proxy::ProxyOptions p;
  p.ladder = {0.03, 0.12};
  EXPECT_DOUBLE_EQ(pipeline::proxy_reach(soup, p), 0.12 * diag);
  p.offset_mode = proxy::OffsetMode::relative;
  p.offset = 0.05;  // within the ladder: same reach, same cached lines
  EXPECT_DOUBLE_EQ(pipeline::proxy_reach(soup, p), 0.12 * diag);
  p.offset = 0.2;
  EXPECT_DOUBLE_EQ(pipeline::proxy_reach(soup, p), 0.2 * diag);
  p.offset_mode = proxy::OffsetMode::absolute;
  p.offset = 1.5 * diag;
  EXPECT_DOUBLE_EQ(pipeline::proxy_reach(soup, p), 1.5 * diag);
}

// Lines stopped at the box are prefixes of the same lines traced out to the
// far sphere (same charges, same seeds; the tracer's target tree spans its
// stop region, so points agree to the FMM's error, measured 1.9e-7 at the
// 24th point of a 3.5-diagonal soup, not bit for bit), and each one ends at
// its first point outside the box, which is farther than kReachMargin *
// reach from every soup point.
TEST(FieldBranchStop, BoxStoppedLinesArePrefixesOfFarLines) {
  const Soup soup = shapes::to_soup(shapes::sphere_with(1.0, 400), 1e-3, 5);
  const double diag = bounding_box(soup).diagonal();
  const std::string hash = geometry_hash(soup);
  pipeline::FieldBranchOptions far = branch_options();
  far.trace.stop_radius = 2.0 * diag;
  pipeline::FieldBranchOptions boxed = branch_options();
  boxed.proxy_reach = 0.12 * diag;
  const auto a = pipeline::run_field_branch(soup, hash, far, nullptr, Progress::none());
  const auto b = pipeline::run_field_branch(soup, hash, boxed, nullptr, Progress::none());
  ASSERT_EQ(a.lines.size(), b.lines.size());
  ASSERT_EQ(a.line_of_corner, b.line_of_corner);
  const Box3 box = pipeline::stop_box_for(soup, boxed.proxy_reach);
  size_t shorter = 0;
  for (size_t l = 0; l < b.lines.size(); ++l) {
    ASSERT_EQ(a.lines.corner[l], b.lines.corner[l]);
    ASSERT_EQ(b.lines.ends[l], field::LineEnd::escaped) << "line " << l;
    const uint32_t b0 = b.lines.offsets[l], b1 = b.lines.offsets[l + 1];
    const uint32_t a0 = a.lines.offsets[l], a1 = a.lines.offsets[l + 1];
    ASSERT_LE(b1 - b0, a1 - a0);
    shorter += (b1 - b0) < (a1 - a0);
    for (uint32_t j = 0; j < b1 - b0; ++j)
      ASSERT_LT(norm(b.lines.points[b0 + j] - a.lines.points[a0 + j]), 1e-5 * diag)
          << "line " << l << " point " << j;
    EXPECT_FALSE(inside(box, b.lines.points[b1 - 1])) << "line " << l;
    EXPECT_TRUE(inside(box, b.lines.points[b1 - 2])) << "line " << l;
  }
  // The far sphere is well outside the box: most lines must get shorter.
  EXPECT_GT(shorter, b.lines.size() / 2);
  EXPECT_LT(b.trace["evaluations"].get<double>(), a.trace["evaluations"].get<double>());
}

// run_map: a re-run with another offset inside the reach reuses the lines;
// an offset beyond it re-traces (the lines would stop before that proxy),
// and every line still lands on the farther proxy.
TEST(FieldBranchStop, OffsetBeyondTheReachRetraces) {
  const Soup soup = shapes::to_soup(shapes::sphere_with(1.0, 300), 1e-3, 6);
  cache::Store store;
  MapOptions o = soupuv::testing::fast_options();
  o.cache = &store;
  o.proxy.ladder = {0.03, 0.05};
  o.proxy.offset = 0.03;
  const MapResult first = run_map(soup, o);
  EXPECT_FALSE(first.diagnostics["stages"]["trace"]["cached"].get<bool>());
  o.proxy.offset = 0.05;
  const MapResult within = run_map(soup, o);
  EXPECT_TRUE(within.diagnostics["stages"]["trace"]["cached"].get<bool>());
  o.proxy.offset = 0.2;
  const MapResult beyond = run_map(soup, o);
  EXPECT_FALSE(beyond.diagnostics["stages"]["trace"]["cached"].get<bool>());
  EXPECT_EQ(beyond.diagnostics["trace"]["fallback"].get<size_t>(), 0u);
  EXPECT_EQ(beyond.diagnostics["trace"]["hit_fraction"].get<double>(), 1.0);
}

// run_map without a cache: lines end at their first proxy crossing, and
// the map is the one the reach box gives (the transfer lands on that
// crossing either way), with fewer evaluations.
TEST(FieldBranchStop, LinesStoppedAtTheProxyGiveTheSameMap) {
  const Soup soup = shapes::to_soup(shapes::sphere_with(1.0, 300), 1e-3, 6);
  MapOptions o = soupuv::testing::fast_options();
  o.cache = nullptr;  // with a cache the lines run on to the reach box
  o.stop_lines_at_proxy = false;
  const MapResult boxed = run_map(soup, o);
  o.stop_lines_at_proxy = true;
  const MapResult stopped = run_map(soup, o);
  ASSERT_EQ(stopped.corner_uvs.size(), boxed.corner_uvs.size());
  for (size_t c = 0; c < stopped.corner_uvs.size(); ++c)
    ASSERT_EQ(norm(stopped.corner_uvs[c] - boxed.corner_uvs[c]), 0.0) << "corner " << c;
  const auto& trace = stopped.diagnostics["trace"];
  EXPECT_EQ(trace["reached"].get<double>(), trace["lines"].get<double>());
  EXPECT_EQ(boxed.diagnostics["trace"]["reached"].get<double>(), 0.0);
  EXPECT_LT(trace["evaluations"].get<double>(), boxed.diagnostics["trace"]["evaluations"].get<double>());
}

// The field branch with a stop surface and a cache: the lines' key names
// the surface, so the same surface reuses them and another re-traces them
// on the cached charges.
TEST(FieldBranchStop, LinesStoppedAtASurfaceAreCachedPerSurface) {
  const Soup soup = shapes::to_soup(shapes::sphere_with(1.0, 300), 1e-3, 6);
  const std::string hash = geometry_hash(soup);
  const TriMesh near_shell = shapes::icosphere(1.1, 2), far_shell = shapes::icosphere(1.3, 2);
  cache::Store store;
  pipeline::FieldBranchOptions o = branch_options();
  o.proxy_reach = 0.5;
  o.stop_surface = [&] { return &near_shell; };
  const auto first = pipeline::run_field_branch(soup, hash, o, &store, Progress::none());
  EXPECT_FALSE(first.lines_cached);
  EXPECT_EQ(first.trace["reached"].get<double>(), double(first.lines.size()));
  const auto again = pipeline::run_field_branch(soup, hash, o, &store, Progress::none());
  EXPECT_TRUE(again.lines_cached);
  o.stop_surface = [&] { return &far_shell; };
  const auto other = pipeline::run_field_branch(soup, hash, o, &store, Progress::none());
  EXPECT_FALSE(other.lines_cached);
  EXPECT_TRUE(other.charges_cached);
  EXPECT_EQ(other.trace["reached"].get<double>(), double(other.lines.size()));
}
