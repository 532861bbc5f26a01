#include <gtest/gtest.h>

#include <random>

#include "soupuv/errors.h"
#include "testing/shapes.h"
#include "soupuv/transfer/transfer.h"
#include "soupuv/geometry/surface_hit_bvh.h"
#include "soupuv/geometry/closest_point.h"
#include "soupuv/geometry/segment_triangle.h"

using namespace soupuv;
using namespace soupuv::transfer;

namespace {

// A sphere proxy with a hand-made two-chart atlas: the upper and lower
// hemispheres (by face centroid) projected orthographically onto the xy plane,
// side by side.
struct SphereProxy {
  proxy::ProxyMesh proxy;
  atlas::Atlas atlas;
};

Vec2 hemisphere_uv(Vec3 p, int chart, double radius) {
  double s = 0.22 / radius;
  return {(chart == 0 ? 0.25 : 0.75) + s * p.x, 0.5 + s * p.y};
}

SphereProxy sphere_proxy(double radius, int level) {
  SphereProxy sp;
  sp.proxy.mesh = shapes::icosphere(radius, level);
  sp.proxy.face_component.assign(sp.proxy.mesh.faces.size(), 0);
  sp.proxy.outer_components = 1;
  const TriMesh& m = sp.proxy.mesh;
  for (const auto& f : m.faces) {
    Vec3 c = (m.vertices[f[0]] + m.vertices[f[1]] + m.vertices[f[2]]) / 3.0;
    int chart = c.z >= 0 ? 0 : 1;
    sp.atlas.face_chart.push_back(chart);
    sp.atlas.face_uvs.push_back({hemisphere_uv(m.vertices[f[0]], chart, radius),
                                 hemisphere_uv(m.vertices[f[1]], chart, radius),
                                 hemisphere_uv(m.vertices[f[2]], chart, radius)});
  }
  sp.atlas.chart_count = 2;
  return sp;
}

// Radial polylines from every corner out to `reach` times its radius.
field::FieldLines radial_lines(const Soup& soup, double reach, int points) {
  field::FieldLines fl;
  for (size_t t = 0; t < soup.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      Vec3 p = soup.corner(t, k);
      for (int i = 0; i < points; ++i)
        fl.points.push_back(p * (1.0 + (reach - 1.0) * i / (points - 1)));
      fl.offsets.push_back(uint32_t(fl.points.size()));
      fl.ends.push_back(field::LineEnd::escaped);
      fl.corner.push_back(uint32_t(3 * t + k));
    }
  return fl;
}

}  // namespace

TEST(SurfaceHitBvh, MatchesBruteForce) {
  TriMesh m = shapes::torus(1.0, 0.4, 24, 12);
  geometry::SurfaceHitBvh bvh(m);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-2, 2);
  for (int q = 0; q < 300; ++q) {
    Vec3 a{u(rng), u(rng), u(rng)}, b{u(rng), u(rng), u(rng)};
    // Slow twin: every face.
    double best_t = INFINITY, best_d = INFINITY;
    for (const auto& f : m.faces) {
      double t;
      std::array<double, 3> bary;
      if (geometry::segment_triangle_hit(a, b, m.vertices[f[0]], m.vertices[f[1]], m.vertices[f[2]], t, bary))
        best_t = std::min(best_t, t);
      best_d = std::min(best_d, geometry::point_triangle_distance(a, m.vertices[f[0]], m.vertices[f[1]],
                                                                  m.vertices[f[2]]));
    }
    geometry::SurfacePoint hit = bvh.first_hit(a, b);
    EXPECT_EQ(hit.found(), std::isfinite(best_t));
    if (hit.found()) {
      EXPECT_NEAR(hit.t, best_t, 1e-12);
    }
    geometry::SurfacePoint cp = bvh.closest_point(a);
    EXPECT_NEAR(cp.t, best_d, 1e-12);
    // Barycentrics reproduce the point.
    const auto& f = m.faces[cp.face];
    Vec3 re = cp.bary[0] * m.vertices[f[0]] + cp.bary[1] * m.vertices[f[1]] + cp.bary[2] * m.vertices[f[2]];
    EXPECT_LT(norm(re - cp.point), 1e-12);
  }
}

TEST(Transfer, RadialLinesOnSphereLandWhereTheyPoint) {
  Soup soup = shapes::to_soup(shapes::icosphere(1.0, 3), 1e-3, 2);
  SphereProxy sp = sphere_proxy(1.5, 4);
  TransferOptions opt;
  opt.fix_chart_boundaries = false;
  TransferResult r = transfer_uvs(soup, radial_lines(soup, 3.0, 12), sp.proxy, sp.atlas, opt);
  EXPECT_EQ(r.hits, soup.triangles.size() * 3);
  EXPECT_EQ(r.fallback_ray + r.fallback_closest, 0u);
  for (size_t c = 0; c < soup.triangles.size() * 3; ++c) {
    Vec3 dir = normalized(soup.corner(c / 3, c % 3));
    // The landing point lies on the ray through the corner, on the proxy.
    EXPECT_LT(norm(cross(normalized(r.landing[c].point), dir)), 1e-9);
    EXPECT_NEAR(norm(r.landing[c].point), 1.5, 0.02);
  }
  EXPECT_GT(r.multi_chart_triangles, 0u) << "equator triangles straddle the charts";
}

TEST(Transfer, ChartFixPutsEveryTriangleOnOneChart) {
  Soup soup = shapes::to_soup(shapes::icosphere(1.0, 3), 1e-3, 2);
  SphereProxy sp = sphere_proxy(1.5, 4);
  TransferResult r = transfer_uvs(soup, radial_lines(soup, 3.0, 12), sp.proxy, sp.atlas);
  EXPECT_GT(r.multi_chart_triangles, 0u);
  EXPECT_EQ(r.corrected_triangles, r.multi_chart_triangles);
  double scale = 0.22 / 1.5;  // UV per length of the hand-made atlas
  for (size_t t = 0; t < soup.triangles.size(); ++t) {
    int c = sp.atlas.face_chart[r.landing[3 * t].face];
    EXPECT_EQ(sp.atlas.face_chart[r.landing[3 * t + 1].face], c);
    EXPECT_EQ(sp.atlas.face_chart[r.landing[3 * t + 2].face], c);
    // No UV triangle spans the gap between the two hemispheres' discs.
    for (int k = 0; k < 3; ++k)
      EXPECT_LT(norm(r.corner_uvs[t][k] - r.corner_uvs[t][(k + 1) % 3]), 20 * scale * 0.2);
  }
}

TEST(Transfer, ShortAndMissingLinesFallBack) {
  Soup soup = shapes::to_soup(shapes::icosphere(1.0, 1), 0, 1);
  SphereProxy sp = sphere_proxy(1.5, 3);
  field::FieldLines fl = radial_lines(soup, 1.2, 4);  // stops inside the proxy
  // Drop the last line entirely: its corner is untraced.
  fl.points.resize(fl.offsets[fl.size() - 1]);
  fl.offsets.pop_back();
  fl.ends.pop_back();
  fl.corner.pop_back();
  TransferResult r = transfer_uvs(soup, fl, sp.proxy, sp.atlas);
  EXPECT_EQ(r.hits, 0u);
  EXPECT_EQ(r.fallback_ray, soup.triangles.size() * 3 - 1);
  EXPECT_EQ(r.untraced_corners, 1u);
  EXPECT_EQ(r.fallback_closest, 1u);
  for (const auto& tri : r.corner_uvs)
    for (Vec2 p : tri) EXPECT_TRUE(p.x >= 0 && p.x <= 1 && p.y >= 0 && p.y <= 1);
}

TEST(Transfer, CancelStops) {
  Soup soup = shapes::to_soup(shapes::icosphere(1.0, 1), 0, 1);
  SphereProxy sp = sphere_proxy(1.5, 2);
  Progress p;
  p.cancel();
  EXPECT_THROW(transfer_uvs(soup, radial_lines(soup, 3, 4), sp.proxy, sp.atlas, {}, p), Error);
}
