// Seam relaxation: the minimum cut against brute force, and build_atlas with
// relax_seams keeping valid charts while its seams get cheaper and move off
// heavily weighted faces.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <random>

#include "atlas/max_flow.h"
#include "atlas_checks.h"
#include "soupuv/atlas/build_atlas.h"
#include "soupuv/errors.h"
#include "testing/shapes.h"

namespace soupuv::atlas {
namespace {

struct Edge {
  int a, b;
  double c;
};

double cut_capacity(const std::vector<Edge>& edges, const std::vector<char>& side) {
  double sum = 0;
  for (const Edge& e : edges)
    if (side[e.a] != side[e.b]) sum += e.c;
  return sum;
}

// Slow twin: every partition of the free nodes.
TEST(MaxFlow, MatchesBruteForceMinCut) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> cap(0.0, 1.0);
  for (int trial = 0; trial < 40; ++trial) {
    const int n = 9, source = 0, sink = n - 1;
    std::vector<Edge> edges;
    for (int a = 0; a < n; ++a)
      for (int b = a + 1; b < n; ++b)
        if (cap(rng) < 0.45) edges.push_back({a, b, cap(rng)});
    FlowGraph g(n);
    for (const Edge& e : edges) g.add_edge(e.a, e.b, e.c);
    const MinCut cut = g.min_cut(source, sink);
    double best = INFINITY;
    for (int mask = 0; mask < (1 << (n - 2)); ++mask) {
      std::vector<char> side(n, 0);
      side[source] = 1;
      for (int v = 1; v < n - 1; ++v) side[v] = (mask >> (v - 1)) & 1;
      best = std::min(best, cut_capacity(edges, side));
    }
    EXPECT_NEAR(cut.capacity, best, 1e-9) << "trial " << trial;
    ASSERT_EQ(cut.source_side.size(), static_cast<size_t>(n));
    EXPECT_TRUE(cut.source_side[source]);
    EXPECT_FALSE(cut.source_side[sink]);
    EXPECT_NEAR(cut_capacity(edges, cut.source_side), best, 1e-9) << "trial " << trial;
  }
}

// Disks, no flips, no overlap: the same independent checks as build_atlas_test.
void expect_valid(const TriMesh& mesh, const AtlasResult& r, const char* name) {
  EXPECT_EQ(r.stats.flipped, 0) << name;
  EXPECT_EQ(r.stats.overlap, 0.0) << name;
  EXPECT_EQ(atlas_checks::overlapping_pairs(r.atlas), 0) << name;
  auto topo = atlas_checks::chart_topology(mesh, r.atlas);
  for (int c = 0; c < r.atlas.chart_count; ++c) {
    EXPECT_EQ(topo[c].euler, 1) << name << " chart " << c;
    EXPECT_EQ(topo[c].boundary_loops, 1) << name << " chart " << c;
  }
}

double weighted_cost(const TriMesh& mesh, const Atlas& atlas, const std::vector<double>& w) {
  // Recomputed from the faces' corners, not the library's topology.
  std::map<std::pair<int, int>, std::vector<int>> faces_of_edge;
  for (size_t f = 0; f < mesh.faces.size(); ++f)
    for (int k = 0; k < 3; ++k) {
      int a = mesh.faces[f][k], b = mesh.faces[f][(k + 1) % 3];
      faces_of_edge[{std::min(a, b), std::max(a, b)}].push_back(static_cast<int>(f));
    }
  double sum = 0;
  for (const auto& [e, fs] : faces_of_edge)
    if (fs.size() == 2 && atlas.face_chart[fs[0]] != atlas.face_chart[fs[1]])
      sum += norm(mesh.vertices[e.first] - mesh.vertices[e.second]) * 0.5 * (w[fs[0]] + w[fs[1]]);
  return sum;
}

AtlasOptions merged_options() {
  AtlasOptions o;  // like the pipeline's atlas: few, merged charts
  o.max_normal_deviation_deg = 70;
  o.merge_charts = true;
  o.merge_max_area_fraction = 1;
  o.merge_min_fill = 0;
  o.merge_max_normal_deviation_deg = 120;
  return o;
}

TEST(SeamRelax, ShortensSeamsAndKeepsChartsValid) {
  const TriMesh torus = shapes::torus_with(1.0, 0.4, 3000);
  AtlasOptions o = merged_options();
  const AtlasResult plain = build_atlas(torus, o, Progress::none());
  o.relax_seams = true;
  const AtlasResult relaxed = build_atlas(torus, o, Progress::none());
  std::printf("torus: seam %.3f -> %.3f (relaxed pairs %d, faces %d), charts %d -> %d\n",
              plain.stats.seam_length, relaxed.stats.seam_length, relaxed.stats.relaxed_pairs,
              relaxed.stats.relaxed_faces, plain.stats.charts, relaxed.stats.charts);
  expect_valid(torus, relaxed, "torus relaxed");
  EXPECT_DOUBLE_EQ(plain.stats.seam_cost, plain.stats.seam_length);  // no weights: cost = length
  EXPECT_GT(relaxed.stats.relaxed_pairs, 0);
  EXPECT_LT(relaxed.stats.seam_length, 0.97 * plain.stats.seam_length);
}

// Faces on one side weigh 8: the relaxation that knows the weights leaves a
// cheaper atlas, by those weights, than the one that does not.
TEST(SeamRelax, SeamsMoveOffHeavyFaces) {
  const TriMesh torus = shapes::torus_with(1.0, 0.4, 3000);
  std::vector<double> w(torus.faces.size(), 1.0);
  for (size_t f = 0; f < torus.faces.size(); ++f) {
    Vec3 c = (torus.vertices[torus.faces[f][0]] + torus.vertices[torus.faces[f][1]] +
              torus.vertices[torus.faces[f][2]]) / 3.0;
    if (c.x + 0.3 * c.y > 0) w[f] = 8;
  }
  AtlasOptions o = merged_options();
  o.relax_seams = true;
  // Where the cut goes is the point here; with the default stretch bound
  // (0.02) the torus's cheaper cuts flatten a little worse and are refused.
  o.relax_max_stretch_increase = 1;
  // Without the narrowing retries: with them this torus ends in another
  // local optimum where blind and aware cost the same by these weights
  // (86.97 vs 86.95; without: 76.9 vs 50.4). The retries gained on the
  // samples (atlas-pipeline mean continuity 0.947 vs 0.942) but make the
  // outcome path-dependent.
  o.relax_narrowings = 0;
  const AtlasResult blind = build_atlas(torus, o, Progress::none());
  o.seam_weight = w;
  const AtlasResult aware = build_atlas(torus, o, Progress::none());
  const double cost_blind = weighted_cost(torus, blind.atlas, w);
  const double cost_aware = weighted_cost(torus, aware.atlas, w);
  std::printf("torus, weights 8 on one side: weighted seam cost blind %.3f, aware %.3f (library %.3f, before relaxing %.3f)\n",
              cost_blind, cost_aware, aware.stats.seam_cost, aware.stats.seam_cost_before_relax);
  expect_valid(torus, aware, "torus weighted");
  EXPECT_NEAR(aware.stats.seam_cost, cost_aware, 1e-9 * cost_aware);
  EXPECT_LT(cost_aware, 0.95 * cost_blind);
}

TEST(SeamRelax, RejectsBadWeights) {
  const TriMesh sphere = shapes::icosphere(1.0, 2);
  AtlasOptions o;
  o.seam_weight.assign(sphere.faces.size() - 1, 1.0);
  EXPECT_THROW(build_atlas(sphere, o, Progress::none()), Error);
  o.seam_weight.assign(sphere.faces.size(), 1.0);
  o.seam_weight[3] = 0;
  EXPECT_THROW(build_atlas(sphere, o, Progress::none()), Error);
}

}  // namespace
}  // namespace soupuv::atlas
