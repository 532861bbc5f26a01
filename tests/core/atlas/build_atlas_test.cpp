// build_atlas on closed shapes: disk charts, no flips, no overlaps, stretch
// and utilisation targets of issue 5, checked independently of the library.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>

#include "atlas_checks.h"
#include "soupuv/atlas/build_atlas.h"
#include "soupuv/errors.h"
#include "test_size.h"
#include "testing/shapes.h"
#include "testing/test_meshes.h"

namespace soupuv::atlas {
namespace {

AtlasResult check_atlas(const std::string& name, const TriMesh& mesh, const AtlasOptions& options = {},
                        double min_utilization = 0.70) {
  AtlasResult r = build_atlas(mesh, options, Progress::none());
  const Atlas& a = r.atlas;
  std::printf("%s: %zu faces, %s\n", name.c_str(), mesh.faces.size(), r.diagnostics().dump().c_str());
  EXPECT_EQ(a.face_uvs.size(), mesh.faces.size());
  // ATLAS_DUMP=dir writes each atlas's UV triangles as text, to look at them.
  if (const char* dir = std::getenv("ATLAS_DUMP")) {
    std::ofstream out(std::string(dir) + "/" + name + ".txt");
    for (size_t f = 0; f < a.face_uvs.size(); ++f) {
      out << a.face_chart[f];
      for (const Vec2& p : a.face_uvs[f]) out << " " << p.x << " " << p.y;
      out << "\n";
    }
  }
  EXPECT_EQ(r.stats.flipped, 0) << name;
  EXPECT_EQ(r.stats.overlap, 0.0) << name;
  EXPECT_LE(r.stats.stretch_l2, 1.10) << name;
  // Issue 5 asks for 0.70 at 2048 / 4 px; the tightest meshes here are the
  // genus-3 ones (many small charts around big arch-shaped ones: 12k 0.713,
  // 40k 0.707 with the bitmap packer).
  EXPECT_GE(r.stats.utilization, min_utilization) << name;

  int flipped = 0, outside = 0, bad_chart = 0;
  for (size_t f = 0; f < a.face_uvs.size(); ++f) {
    flipped += atlas_checks::signed_area(a.face_uvs[f]) <= 0;
    for (const Vec2& p : a.face_uvs[f]) outside += !(p.x >= 0 && p.x <= 1 && p.y >= 0 && p.y <= 1);
    bad_chart += !(a.face_chart[f] >= 0 && a.face_chart[f] < a.chart_count);
  }
  EXPECT_EQ(flipped, 0) << name;
  EXPECT_EQ(outside, 0) << name;
  EXPECT_EQ(bad_chart, 0) << name;
  if (bad_chart) return r;
  EXPECT_EQ(atlas_checks::overlapping_pairs(a), 0) << name;
  auto topo = atlas_checks::chart_topology(mesh, a);
  for (int c = 0; c < a.chart_count; ++c) {
    EXPECT_EQ(topo[c].euler, 1) << name << " chart " << c;
    EXPECT_EQ(topo[c].boundary_loops, 1) << name << " chart " << c;
  }
  return r;
}

TEST(BuildAtlas, Sphere) { check_atlas("sphere", shapes::sphere_with(1.0, 6000)); }
TEST(BuildAtlas, Icosphere) { check_atlas("icosphere", shapes::icosphere(2.0, 4)); }
TEST(BuildAtlas, Torus) { check_atlas("torus", shapes::torus_with(1.0, 0.3, 5000)); }
TEST(BuildAtlas, ThinTorus) { check_atlas("thin torus", shapes::torus(1.0, 0.1, 96, 16)); }
TEST(BuildAtlas, Cube) {
  AtlasResult r = check_atlas("cube", shapes::cube(2.0, 12));
  // Flat faces and 90-degree creases: the six faces are the natural charts
  // (packing may halve some of them afterwards).
  EXPECT_EQ(r.stats.charts - r.stats.packing_splits, 6);
  EXPECT_LT(r.stats.stretch_l2, 1.0 + 1e-6);
}
TEST(BuildAtlas, Cylinder) { check_atlas("cylinder", shapes::cylinder(0.5, 2.0, 48, 16, 6)); }
TEST(BuildAtlas, GenusThree) { check_atlas("genus 3", test_meshes::fused_tori(3, 12000)); }
// The two meshes that missed 0.70 with the column packer alone (0.684 and
// 0.695, session 2); the 100k genus-3 row is in soupuv-bench atlas.
// Utilisation at size; GenusThree and Torus walk the same code smaller.
TEST(BuildAtlas, GenusThreeOf40k) {
  SOUPUV_SKIP_IF_REDUCED("utilisation at 40k faces");
  check_atlas("genus 3 40k", test_meshes::fused_tori(3, 40000));
}
TEST(BuildAtlas, TorusOf51k) {
  SOUPUV_SKIP_IF_REDUCED("utilisation at 51k faces");
  check_atlas("torus 51k", shapes::torus_with(1.0, 0.3, 51200));
}
TEST(BuildAtlas, DrilledBlock) { check_atlas("drilled block", test_meshes::drilled_block(10000)); }
TEST(BuildAtlas, TwoComponents) {
  TriMesh a = shapes::sphere_with(1.0, 2000), b = shapes::torus_with(1.0, 0.3, 2000);
  shapes::translate(b, {4, 0, 0});
  int offset = static_cast<int>(a.vertices.size());
  a.vertices.insert(a.vertices.end(), b.vertices.begin(), b.vertices.end());
  for (auto f : b.faces) a.faces.push_back({f[0] + offset, f[1] + offset, f[2] + offset});
  check_atlas("sphere + torus", a);
}
// Chart merging (off by default): fewer charts and shorter seams, and every
// merged chart is still a disk without flips or overlap (check_atlas). It
// trades utilisation for seams (torus 5k: 0.715 -> 0.67, seams -33%
// measured), so the guard here is looser than 0.70.
TEST(BuildAtlas, MergingShortensSeams) {
  TriMesh torus = shapes::torus_with(1.0, 0.3, 2000);
  AtlasOptions merge;
  merge.merge_charts = true;
  AtlasResult plain = build_atlas(torus, {}, Progress::none());
  AtlasResult merged = check_atlas("torus merged", torus, merge, 0.6);
  EXPECT_GT(merged.stats.chart_merges, 0);
  EXPECT_LT(merged.stats.charts, plain.stats.charts);
  EXPECT_LT(merged.stats.seam_length, 0.8 * plain.stats.seam_length);
  EXPECT_LE(merged.stats.stretch_l2, merge.max_stretch);
}

// Merged charts are few and big, so utilisation falls below
// packing_split_below; the packing rounds then halved the biggest charts
// again and the seams came back longer than without merging (session 3's
// pipeline run: suzanne 22 -> 24 charts, 14 packing splits). With merging on,
// no packing split may undo a merge.
TEST(BuildAtlas, PackingKeepsMergedCharts) {
  TriMesh sphere = shapes::sphere_with(1.0, 2000);
  AtlasOptions merge;
  merge.max_normal_deviation_deg = 70;  // the pipeline's budget
  merge.merge_charts = true;
  merge.merge_max_area_fraction = 1;
  merge.merge_min_fill = 0;
  AtlasOptions plain = merge;
  plain.merge_charts = false;
  AtlasResult p = build_atlas(sphere, plain, Progress::none());
  AtlasResult m = check_atlas("sphere merged", sphere, merge, 0.4);
  EXPECT_GT(m.stats.chart_merges, 0);
  EXPECT_EQ(m.stats.packing_splits, 0);
  EXPECT_LT(m.stats.charts, p.stats.charts);
  EXPECT_LT(m.stats.seam_length, p.stats.seam_length);
}

// The widest turn of a face normal from its chart's area-weighted mean
// normal, over all charts (degrees).
double widest_chart_cone(const TriMesh& mesh, const Atlas& atlas) {
  std::vector<Vec3> mean(atlas.chart_count, Vec3{0, 0, 0});
  std::vector<Vec3> normal(mesh.faces.size());
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    const auto& t = mesh.faces[f];
    const Vec3 n = cross(mesh.vertices[t[1]] - mesh.vertices[t[0]], mesh.vertices[t[2]] - mesh.vertices[t[0]]);
    mean[atlas.face_chart[f]] += n;  // |n| = twice the area: area-weighted
    normal[f] = normalized(n);
  }
  double widest = 0;
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    const double c = std::clamp(dot(normal[f], normalized(mean[atlas.face_chart[f]])), -1.0, 1.0);
    widest = std::max(widest, std::acos(c) * 180 / M_PI);
  }
  return widest;
}

// Unlimited merging turns a sphere into a few charts that wrap far around
// it; the normal-cone limit keeps every merged chart within its cone (the
// segmentation's own charts stay within 1.5 x its 40 deg budget).
TEST(BuildAtlas, MergeConeLimitsChartsWrappingAround) {
  TriMesh sphere = shapes::sphere_with(1.0, 2000);
  AtlasOptions o;
  o.max_normal_deviation_deg = 40;
  o.merge_charts = true;
  o.merge_max_area_fraction = 1;
  o.merge_min_fill = 0;
  AtlasResult wide = build_atlas(sphere, o, Progress::none());
  o.merge_max_normal_deviation_deg = 60;
  AtlasResult coned = check_atlas("sphere merged within 60 deg", sphere, o, 0.4);
  EXPECT_GT(widest_chart_cone(sphere, wide.atlas), 60.0);
  EXPECT_GT(coned.stats.chart_merges, 0);
  EXPECT_LE(widest_chart_cone(sphere, coned.atlas), 60.0 + 1e-9);
  EXPECT_GT(coned.stats.charts, wide.stats.charts);
}

// merge_max_stretch lets merged charts flatten worse than the segmentation's
// budget (the pipeline's candidates trade the atlas's stretch for seams):
// no more charts and shorter seams, every chart still a disk without flips or
// overlap, the stretch within the merge budget and not within the old one.
TEST(BuildAtlas, MergeStretchBudgetTradesStretchForSeams) {
  TriMesh sphere = shapes::sphere_with(1.0, 2000);
  AtlasOptions o;
  o.max_normal_deviation_deg = 70;
  o.merge_charts = true;
  o.merge_max_area_fraction = 1;
  o.merge_min_fill = 0;
  AtlasResult tight = build_atlas(sphere, o, Progress::none());
  o.merge_max_stretch = 1.3;
  AtlasResult loose = build_atlas(sphere, o, Progress::none());
  std::printf("sphere merged at 1.05 / 1.3: %d / %d charts, seams %.3f / %.3f, L2 %.3f / %.3f\n",
              tight.stats.charts, loose.stats.charts, tight.stats.seam_length, loose.stats.seam_length,
              tight.stats.stretch_l2, loose.stats.stretch_l2);
  // Measured: 2 / 2 charts, seams 8.29 / 4.88, L2 1.016 / 1.133.
  EXPECT_LE(loose.stats.charts, tight.stats.charts);
  EXPECT_LT(loose.stats.seam_length, 0.8 * tight.stats.seam_length);
  EXPECT_LE(tight.stats.stretch_l2, o.max_stretch);
  EXPECT_GT(loose.stats.stretch_l2, o.max_stretch);
  EXPECT_LE(loose.stats.stretch_l2, o.merge_max_stretch);
  EXPECT_EQ(loose.stats.flipped, 0);
  EXPECT_EQ(atlas_checks::overlapping_pairs(loose.atlas), 0);
  for (const auto& c : atlas_checks::chart_topology(sphere, loose.atlas)) {
    EXPECT_EQ(c.euler, 1);
    EXPECT_EQ(c.boundary_loops, 1);
  }
  o.merge_max_stretch = 0.5;
  EXPECT_THROW(build_atlas(sphere, o, Progress::none()), Error);
}

TEST(BuildAtlas, SmallTextureKeepsPadding) {
  AtlasOptions o;
  o.texture_size = 256;
  o.padding_px = 4;
  AtlasResult r = build_atlas(shapes::torus_with(1.0, 0.3, 2000), o, Progress::none());
  // Faces of different charts keep at least the padding apart: test every
  // pair of corners from different charts against the gap in texels.
  const Atlas& a = r.atlas;
  double closest = INFINITY;
  for (size_t f = 0; f < a.face_uvs.size(); ++f)
    for (size_t g = f + 1; g < a.face_uvs.size(); ++g) {
      if (a.face_chart[f] == a.face_chart[g]) continue;
      for (const Vec2& p : a.face_uvs[f])
        for (const Vec2& q : a.face_uvs[g]) closest = std::min(closest, norm(p - q) * o.texture_size);
    }
  EXPECT_GE(closest, 4.0 - 1e-9);
}

TEST(BuildAtlas, RejectsOpenMesh) {
  TriMesh m = shapes::pipe(1.0, 2.0, 16, 4);
  try {
    build_atlas(m, {}, Progress::none());
    FAIL() << "an open mesh was accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::invalid_input);
  }
}

TEST(BuildAtlas, RejectsEmptyMesh) {
  try {
    build_atlas(TriMesh{}, {}, Progress::none());
    FAIL() << "an empty mesh was accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::no_triangles);
  }
}

TEST(BuildAtlas, Cancels) {
  Progress p;
  p.cancel();
  try {
    build_atlas(shapes::sphere_with(1.0, 2000), {}, p);
    FAIL() << "a canceled build finished";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::canceled);
  }
}

}  // namespace
}  // namespace soupuv::atlas

namespace soupuv::atlas {
namespace {

// Timing of a 100k-face mesh; run with --gtest_also_run_disabled_tests.
TEST(BuildAtlasLarge, DISABLED_Genus3Of100k) {
  TriMesh mesh = test_meshes::fused_tori(3, 100000);
  AtlasResult r = build_atlas(mesh, {}, Progress::none());
  std::printf("%zu faces: %s\n", mesh.faces.size(), r.diagnostics().dump().c_str());
}

TEST(BuildAtlasLarge, DISABLED_SphereOf100k) {
  TriMesh mesh = shapes::sphere_with(1.0, 100000);
  AtlasResult r = build_atlas(mesh, {}, Progress::none());
  std::printf("%zu faces: %s\n", mesh.faces.size(), r.diagnostics().dump().c_str());
}

}  // namespace
}  // namespace soupuv::atlas
