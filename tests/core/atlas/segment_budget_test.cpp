// Choosing among segmentation budgets: with seam weights, build_atlas builds
// the whole atlas for each budget and keeps the one whose weighted seam
// length is least; without weights it builds only the first. Checked against
// separate builds, one per budget (the slow twin), and the weighted cost
// recomputed from the faces.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include "atlas_checks.h"
#include "soupuv/atlas/build_atlas.h"
#include "soupuv/errors.h"
#include "testing/shapes.h"

namespace soupuv::atlas {
namespace {

AtlasOptions pipeline_like() {
  AtlasOptions o;  // few merged charts, relaxed seams, like the pipeline's atlas
  o.max_normal_deviation_deg = 70;
  o.merge_charts = true;
  o.merge_max_area_fraction = 1;
  o.merge_min_fill = 0;
  o.merge_max_normal_deviation_deg = 120;
  o.relax_seams = true;
  o.relax_band = 0.6;
  return o;
}

// Weights that differ from place to place, so budgets are told apart by more
// than seam length: faces above the torus's mid plane weigh 4.
std::vector<double> uneven_weights(const TriMesh& mesh) {
  std::vector<double> w(mesh.faces.size(), 1.0);
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    const Vec3 c = (mesh.vertices[mesh.faces[f][0]] + mesh.vertices[mesh.faces[f][1]] +
                    mesh.vertices[mesh.faces[f][2]]) / 3.0;
    if (c.z > 0.1) w[f] = 4;
  }
  return w;
}

double weighted_cost(const TriMesh& mesh, const Atlas& atlas, const std::vector<double>& w) {
  std::map<std::pair<int, int>, std::vector<int>> faces_of_edge;
  for (size_t f = 0; f < mesh.faces.size(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int a = mesh.faces[f][k], b = mesh.faces[f][(k + 1) % 3];
      faces_of_edge[{std::min(a, b), std::max(a, b)}].push_back(static_cast<int>(f));
    }
  double sum = 0;
  for (const auto& [e, fs] : faces_of_edge)
    if (fs.size() == 2 && atlas.face_chart[fs[0]] != atlas.face_chart[fs[1]])
      sum += norm(mesh.vertices[e.first] - mesh.vertices[e.second]) * 0.5 * (w[fs[0]] + w[fs[1]]);
  return sum;
}

TEST(SegmentBudgets, KeepsTheCheapestOfSeparateBuilds) {
  const TriMesh torus = shapes::torus_with(1.0, 0.4, 1200);
  AtlasOptions o = pipeline_like();
  o.seam_weight = uneven_weights(torus);
  const std::vector<double> budgets = {70, 45, 85};
  std::vector<double> cost;
  for (double b : budgets) {
    AtlasOptions one = o;
    one.max_normal_deviation_deg = b;
    const AtlasResult r = build_atlas(torus, one, Progress::none());
    EXPECT_EQ(r.stats.segment_budgets_tried, 1);
    cost.push_back(weighted_cost(torus, r.atlas, o.seam_weight));
  }
  o.alternative_normal_deviations_deg = {45, 85};
  const AtlasResult chosen = build_atlas(torus, o, Progress::none());
  const size_t best = std::min_element(cost.begin(), cost.end()) - cost.begin();
  std::printf("torus: weighted seam cost at 70 / 45 / 85 deg: %.3f / %.3f / %.3f; chosen %.0f deg, %.3f\n",
              cost[0], cost[1], cost[2], chosen.stats.segment_angle_deg, chosen.stats.seam_cost);
  EXPECT_EQ(chosen.stats.segment_budgets_tried, 3);
  EXPECT_EQ(chosen.stats.segment_angle_deg, budgets[best]);
  EXPECT_NEAR(weighted_cost(torus, chosen.atlas, o.seam_weight), cost[best], 1e-9 * cost[best]);
  EXPECT_NEAR(chosen.stats.seam_cost, cost[best], 1e-9 * cost[best]);
  // The budgets must really give different atlases, or this proves nothing.
  EXPECT_GT(*std::max_element(cost.begin(), cost.end()), 1.01 * cost[best]);
  // The kept atlas is a valid one: disks without flips or overlap.
  EXPECT_EQ(chosen.stats.flipped, 0);
  EXPECT_EQ(atlas_checks::overlapping_pairs(chosen.atlas), 0);
  for (const auto& t : atlas_checks::chart_topology(torus, chosen.atlas)) {
    EXPECT_EQ(t.euler, 1);
    EXPECT_EQ(t.boundary_loops, 1);
  }
}

TEST(SegmentBudgets, WithoutWeightsOnlyTheFirstBudget) {
  const TriMesh torus = shapes::torus_with(1.0, 0.4, 1200);
  AtlasOptions o = pipeline_like();
  const AtlasResult plain = build_atlas(torus, o, Progress::none());
  o.alternative_normal_deviations_deg = {45, 85};
  const AtlasResult r = build_atlas(torus, o, Progress::none());
  EXPECT_EQ(r.stats.segment_budgets_tried, 1);
  EXPECT_EQ(r.stats.segment_angle_deg, 70);
  EXPECT_EQ(r.atlas.face_chart, plain.atlas.face_chart);
}

TEST(SegmentBudgets, RefusesBudgetsOutsideTheRange) {
  const TriMesh torus = shapes::torus_with(1.0, 0.4, 200);
  AtlasOptions o = pipeline_like();
  o.alternative_normal_deviations_deg = {90};
  EXPECT_THROW(build_atlas(torus, o, Progress::none()), Error);
}

}  // namespace
}  // namespace soupuv::atlas
