#include "soupuv/transfer/chart_fix.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>

#include "soupuv/transfer/transfer.h"

namespace soupuv::transfer {

namespace {

double uv_area(Vec2 a, Vec2 b, Vec2 c) { return 0.5 * std::abs(cross(b - a, c - a)); }

// UV units per 3D length over the whole atlas, when the atlas does not say.
double atlas_scale(const TriMesh& mesh, const atlas::Atlas& atlas) {
  if (atlas.uv_per_length > 0) return atlas.uv_per_length;
  double a3 = 0, auv = 0;
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    const auto& t = mesh.faces[f];
    a3 += 0.5 * norm(cross(mesh.vertices[t[1]] - mesh.vertices[t[0]],
                           mesh.vertices[t[2]] - mesh.vertices[t[0]]));
    auv += uv_area(atlas.face_uvs[f][0], atlas.face_uvs[f][1], atlas.face_uvs[f][2]);
  }
  return a3 > 0 ? std::sqrt(auv / a3) : 1.0;
}

// Barycentric coordinates of p projected onto the plane of face f (negative
// outside the face): evaluating the face's UVs with them extends the chart's
// map linearly across its boundary.
std::array<double, 3> plane_barycentric(const TriMesh& mesh, int f, Vec3 p) {
  const auto& t = mesh.faces[f];
  Vec3 a = mesh.vertices[t[0]], e1 = mesh.vertices[t[1]] - a, e2 = mesh.vertices[t[2]] - a;
  Vec3 q = p - a;
  double d11 = dot(e1, e1), d12 = dot(e1, e2), d22 = dot(e2, e2);
  double det = d11 * d22 - d12 * d12;
  if (!(det > 0)) return {1, 0, 0};
  double q1 = dot(q, e1), q2 = dot(q, e2);
  double v = (d22 * q1 - d12 * q2) / det, w = (d11 * q2 - d12 * q1) / det;
  return {1 - v - w, v, w};
}

}  // namespace

ChartFixResult fix_chart_boundaries(const Soup& soup, const proxy::ProxyMesh& proxy,
                                    const atlas::Atlas& atlas, std::vector<SurfacePoint>& landing,
                                    std::vector<std::array<Vec2, 3>>& corner_uvs,
                                    Progress& progress) {
  ChartFixResult r;
  const TriMesh& mesh = proxy.mesh;
  auto chart_of = [&](size_t corner) { return atlas.face_chart[landing[corner].face]; };

  std::vector<uint32_t> mixed;
  for (size_t t = 0; t < soup.triangles.size(); ++t) {
    int c0 = chart_of(3 * t), c1 = chart_of(3 * t + 1), c2 = chart_of(3 * t + 2);
    if (c0 != c1 || c0 != c2) mixed.push_back(uint32_t(t));
  }
  r.multi_chart_triangles = mixed.size();
  if (mixed.empty()) return r;

  // One BVH per chart that some mixed triangle names, built on demand.
  std::vector<std::vector<int>> chart_faces(atlas.chart_count);
  for (size_t f = 0; f < mesh.faces.size(); ++f) chart_faces[atlas.face_chart[f]].push_back(int(f));
  std::map<int, std::unique_ptr<TriangleBvh>> chart_bvh;
  auto bvh_of = [&](int chart) -> const TriangleBvh& {
    auto& slot = chart_bvh[chart];
    if (!slot) slot = std::make_unique<TriangleBvh>(mesh, chart_faces[chart]);
    return *slot;
  };

  const double scale = atlas_scale(mesh, atlas);
  const double scale2 = scale * scale;
  for (size_t i = 0; i < mixed.size(); ++i) {
    if ((i & 1023) == 0) progress.update("transfer", 0.8 + 0.2 * double(i) / double(mixed.size()));
    const uint32_t t = mixed[i];
    const double area3 = triangle_area(soup, t);
    int charts[3] = {chart_of(3 * t), chart_of(3 * t + 1), chart_of(3 * t + 2)};
    double best_err = INFINITY;
    std::array<SurfacePoint, 3> best_land;
    std::array<Vec2, 3> best_uv;
    for (int k = 0; k < 3; ++k) {
      int chart = charts[k];
      if ((k > 0 && chart == charts[0]) || (k > 1 && chart == charts[1])) continue;  // tried
      std::array<SurfacePoint, 3> land;
      std::array<Vec2, 3> uv;
      for (int j = 0; j < 3; ++j) {
        if (charts[j] == chart) {
          land[j] = landing[3 * t + j];
          uv[j] = atlas_uv(atlas, land[j]);
          continue;
        }
        // The closest point of the chart sits on its boundary; the paper
        // takes its UV, which squashes the triangle against the seam. We
        // extend the boundary face's linear map to the landing point instead
        // (continuous across the seam, exact where the proxy is flat), as
        // long as that stays within four face sizes of the boundary.
        const Vec3 p = landing[3 * t + j].point;
        land[j] = bvh_of(chart).closest_point(p);
        uv[j] = atlas_uv(atlas, land[j]);
        const auto& f = mesh.faces[land[j].face];
        double size = std::max({norm(mesh.vertices[f[1]] - mesh.vertices[f[0]]),
                                norm(mesh.vertices[f[2]] - mesh.vertices[f[1]]),
                                norm(mesh.vertices[f[0]] - mesh.vertices[f[2]])});
        if (norm(p - land[j].point) <= 4 * size) {
          SurfacePoint extended = land[j];
          extended.bary = plane_barycentric(mesh, land[j].face, p);
          uv[j] = atlas_uv(atlas, extended);
          // A chart packed against the atlas border must not extend past it.
          uv[j].x = std::clamp(uv[j].x, 0.0, 1.0);
          uv[j].y = std::clamp(uv[j].y, 0.0, 1.0);
        }
      }
      double err = std::abs(uv_area(uv[0], uv[1], uv[2]) / scale2 - area3);
      if (err < best_err) {
        best_err = err;
        best_land = land;
        best_uv = uv;
      }
    }
    bool changed = false;
    for (int j = 0; j < 3; ++j) {
      changed |= best_land[j].face != landing[3 * t + j].face;
      landing[3 * t + j] = best_land[j];
    }
    corner_uvs[t] = best_uv;
    r.corrected_triangles += changed;
  }
  return r;
}

}  // namespace soupuv::transfer
