#include "atlas/atlas_metrics.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "soupuv/geometry/triangle_stretch.h"

namespace soupuv::atlas {
namespace {

double corner_angle(Vec3 a, Vec3 b, Vec3 c) { return std::atan2(norm(cross(b - a, c - a)), dot(b - a, c - a)); }
double corner_angle(Vec2 a, Vec2 b, Vec2 c) { return std::atan2(std::fabs(cross(b - a, c - a)), dot(b - a, c - a)); }

}  // namespace

double raster_overlap(const std::vector<std::array<Vec2, 3>>& face_uvs, int resolution) {
  std::vector<uint8_t> count(static_cast<size_t>(resolution) * resolution, 0);
  for (const auto& uv : face_uvs) {
    Vec2 p[3];
    for (int k = 0; k < 3; ++k) p[k] = uv[k] * static_cast<double>(resolution);
    double sign = cross(p[1] - p[0], p[2] - p[0]) >= 0 ? 1 : -1;
    int x0 = std::max(0, static_cast<int>(std::floor(std::min({p[0].x, p[1].x, p[2].x}))));
    int x1 = std::min(resolution - 1, static_cast<int>(std::floor(std::max({p[0].x, p[1].x, p[2].x}))));
    int y0 = std::max(0, static_cast<int>(std::floor(std::min({p[0].y, p[1].y, p[2].y}))));
    int y1 = std::min(resolution - 1, static_cast<int>(std::floor(std::max({p[0].y, p[1].y, p[2].y}))));
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) {
        Vec2 c{x + 0.5, y + 0.5};
        // Strictly inside only: a centre on an edge shared by two faces of
        // one chart must not count as covered twice.
        bool inside = true;
        for (int k = 0; k < 3 && inside; ++k) inside = sign * cross(p[(k + 1) % 3] - p[k], c - p[k]) > 0;
        if (inside) {
          uint8_t& n = count[static_cast<size_t>(y) * resolution + x];
          if (n < 255) ++n;
        }
      }
  }
  size_t covered = 0, twice = 0;
  for (uint8_t n : count) { covered += n >= 1; twice += n >= 2; }
  return covered ? static_cast<double>(twice) / covered : 0.0;
}

AtlasMetrics measure_atlas(const TriMesh& mesh, const Atlas& atlas) {
  AtlasMetrics m;
  Box3 box;
  for (const Vec3& p : mesh.vertices) box.add(p);
  const double tiny = 1e-14 * box.diagonal() * box.diagonal();
  double sum_l2 = 0, a3 = 0, a2 = 0, gamma = 0, angle_sum = 0;
  long long corners = 0;
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    std::array<Vec3, 3> q = {mesh.vertices[mesh.faces[f][0]], mesh.vertices[mesh.faces[f][1]],
                             mesh.vertices[mesh.faces[f][2]]};
    const auto& p = atlas.face_uvs[f];
    geometry::TriangleStretch s = geometry::triangle_stretch(q, p);
    if (s.area3d <= tiny) continue;
    if (s.area_uv <= 0) { ++m.flipped; continue; }
    sum_l2 += s.l2_squared * s.area3d;
    a3 += s.area3d;
    a2 += s.area_uv;
    gamma = std::max(gamma, s.gamma_max);
    for (int k = 0; k < 3; ++k) {
      int i = (k + 1) % 3, j = (k + 2) % 3;
      angle_sum += std::fabs(corner_angle(q[k], q[i], q[j]) - corner_angle(p[k], p[i], p[j]));
      ++corners;
    }
  }
  if (a3 > 0) {
    double normalise = std::sqrt(a2 / a3);
    m.stretch_l2 = std::sqrt(sum_l2 / a3) * normalise;
    m.stretch_linf = gamma * normalise;
  }
  m.angle_distortion_deg = corners ? angle_sum / corners * 180.0 / M_PI : 0.0;
  m.utilization = a2;
  m.overlap = raster_overlap(atlas.face_uvs, atlas.texture_size);
  return m;
}

}  // namespace soupuv::atlas
