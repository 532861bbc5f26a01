// Seam hints (paper §6): the requested polylines become seams of the atlas,
// along mesh edges near the requested points, and the curvature term pulls
// paths onto creases.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <set>

#include "soupuv/atlas/build_atlas.h"
#include "testing/shapes.h"

namespace soupuv::atlas {
namespace {

// True if the two faces on mesh edge (a, b) are in different charts or give a
// or b different UVs: the texture is cut there.
bool is_seam(const TriMesh& mesh, const Atlas& atlas, int a, int b) {
  std::vector<std::pair<int, std::map<int, Vec2>>> sides;
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    std::map<int, Vec2> uv;
    for (int k = 0; k < 3; ++k) uv[mesh.faces[f][k]] = atlas.face_uvs[f][k];
    if (uv.count(a) && uv.count(b)) sides.push_back({atlas.face_chart[f], uv});
  }
  if (sides.size() != 2) return false;
  if (sides[0].first != sides[1].first) return true;
  for (int v : {a, b})
    if (norm(sides[0].second[v] - sides[1].second[v]) > 1e-12) return true;
  return false;
}

// Distance from p to the polyline.
double to_polyline(Vec3 p, const std::vector<Vec3>& line) {
  double best = INFINITY;
  for (size_t i = 0; i + 1 < line.size(); ++i) {
    Vec3 d = line[i + 1] - line[i];
    double t = std::clamp(dot(p - line[i], d) / norm2(d), 0.0, 1.0);
    best = std::min(best, norm(p - (line[i] + t * d)));
  }
  return best;
}

// The seam edges form one path from the vertex nearest the first point to the
// vertex nearest the last.
void expect_path(const TriMesh& mesh, const std::vector<std::array<int, 2>>& edges,
                 Vec3 first, Vec3 last) {
  std::map<int, int> degree;
  for (auto e : edges) { ++degree[e[0]]; ++degree[e[1]]; }
  std::vector<int> ends;
  for (auto [v, d] : degree) {
    EXPECT_LE(d, 2) << "the path branches at vertex " << v;
    if (d == 1) ends.push_back(v);
  }
  ASSERT_EQ(ends.size(), 2u);
  auto nearest = [&](Vec3 p) {
    int best = 0;
    for (size_t v = 0; v < mesh.vertices.size(); ++v)
      if (norm(mesh.vertices[v] - p) < norm(mesh.vertices[best] - p)) best = static_cast<int>(v);
    return best;
  };
  std::set<int> want{nearest(first), nearest(last)}, got(ends.begin(), ends.end());
  EXPECT_EQ(want, got);
}

TEST(SeamHints, SphereMeridianBecomesSeam) {
  TriMesh mesh = shapes::sphere_with(1.0, 4000);
  SeamHint hint;
  for (double deg : {35.0, 60.0, 90.0, 120.0, 145.0}) {
    double t = deg * M_PI / 180;
    hint.points.push_back({std::sin(t) * std::cos(0.3), std::sin(t) * std::sin(0.3), std::cos(t)});
  }
  AtlasOptions o;
  o.seam_hints = {hint};
  AtlasResult r = build_atlas(mesh, o, Progress::none());
  ASSERT_GT(r.forced_seams.size(), 5u);
  EXPECT_EQ(r.stats.seam_edges, static_cast<int>(r.forced_seams.size()));
  expect_path(mesh, r.forced_seams, hint.points.front(), hint.points.back());
  double edge = 2 * M_PI / std::sqrt(2.0 * 4000);  // about one edge length
  for (auto e : r.forced_seams) {
    EXPECT_TRUE(is_seam(mesh, r.atlas, e[0], e[1])) << e[0] << "-" << e[1];
    EXPECT_LT(to_polyline(mesh.vertices[e[0]], hint.points), 2 * edge);
  }
  EXPECT_EQ(r.stats.flipped, 0);
  EXPECT_EQ(r.stats.overlap, 0.0);
}

TEST(SeamHints, CubeFaceIsCutAlongTheLine) {
  TriMesh mesh = shapes::cube(2.0, 12);
  SeamHint hint{{{-1, 0, 1}, {1, 0, 1}}};
  AtlasOptions o;
  o.seam_hints = {hint};
  AtlasResult r = build_atlas(mesh, o, Progress::none());
  ASSERT_EQ(r.forced_seams.size(), 12u);  // the straight grid line across the top face
  expect_path(mesh, r.forced_seams, hint.points.front(), hint.points.back());
  for (auto e : r.forced_seams) {
    for (int v : e) {
      EXPECT_NEAR(mesh.vertices[v].y, 0.0, 1e-12);
      EXPECT_NEAR(mesh.vertices[v].z, 1.0, 1e-12);
    }
    EXPECT_TRUE(is_seam(mesh, r.atlas, e[0], e[1]));
  }
}

TEST(SeamHints, CurvatureTermPrefersCreases) {
  // Between opposite corners of the top face, against the direction of the
  // face diagonals: every path along edges through the face is as long as the
  // one along two crease edges, so the curvature term decides.
  TriMesh mesh = shapes::cube(2.0, 6);
  SeamHint hint{{{1, -1, 1}, {-1, 1, 1}}};
  auto crease_fraction = [&](const AtlasResult& r) {
    int crease = 0;
    for (auto e : r.forced_seams) {
      Vec3 m = 0.5 * (mesh.vertices[e[0]] + mesh.vertices[e[1]]);
      int extreme = (std::fabs(std::fabs(m.x) - 1) < 1e-9) + (std::fabs(std::fabs(m.y) - 1) < 1e-9) +
                    (std::fabs(std::fabs(m.z) - 1) < 1e-9);
      crease += extreme >= 2;
    }
    return static_cast<double>(crease) / r.forced_seams.size();
  };
  AtlasOptions o;
  o.seam_hints = {hint};
  o.alpha = 1;
  o.beta = 0;
  AtlasResult r = build_atlas(mesh, o, Progress::none());
  ASSERT_EQ(r.forced_seams.size(), 12u);
  EXPECT_EQ(crease_fraction(r), 1.0);
  expect_path(mesh, r.forced_seams, hint.points.front(), hint.points.back());
}

}  // namespace
}  // namespace soupuv::atlas
