#include "testing/test_meshes.h"

#include <algorithm>
#include <cmath>

#include "soupuv/proxy/marching_tetrahedra.h"
#include "soupuv/proxy/narrow_band.h"

namespace soupuv::test_meshes {

TriMesh march(const std::function<double(Vec3)>& f, Vec3 lo, Vec3 hi, int cells, int smoothing) {
  // The proxy's own marching tetrahedra (proxy/marching_tetrahedra.h) over a
  // dense band: every grid corner sampled, every sign-changing cell listed.
  Vec3 ext = hi - lo;
  double h = std::max({ext.x, ext.y, ext.z}) / cells;
  const int nx = static_cast<int>(std::ceil(ext.x / h)) + 1;
  const int ny = static_cast<int>(std::ceil(ext.y / h)) + 1;
  const int nz = static_cast<int>(std::ceil(ext.z / h)) + 1;
  proxy::NarrowBand band;
  band.origin = lo;
  band.cell = h;
  band.dims = {nx - 1, ny - 1, nz - 1};
  // Keys sort by (k, j, i), the order of these loops.
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        band.corner_keys.push_back(proxy::grid_key(i, j, k));
        band.corner_values.push_back(f(lo + Vec3{i * h, j * h, k * h}));
      }
  auto value = [&](int i, int j, int k) { return band.corner_values[(size_t(k) * ny + j) * nx + i]; };
  for (int k = 0; k + 1 < nz; ++k)
    for (int j = 0; j + 1 < ny; ++j)
      for (int i = 0; i + 1 < nx; ++i) {
        int inside = 0;
        for (int c = 0; c < 8; ++c) inside += value(i + (c & 1), j + ((c >> 1) & 1), k + (c >> 2)) < 0;
        if (inside > 0 && inside < 8) band.cells.push_back(proxy::grid_key(i, j, k));
      }
  TriMesh m = proxy::marching_tetrahedra(band, Progress::none());

  std::vector<std::vector<int>> neighbors(m.vertices.size());
  for (const auto& t : m.faces)
    for (int e = 0; e < 3; ++e) neighbors[t[e]].push_back(t[(e + 1) % 3]);
  for (int pass = 0; pass < smoothing; ++pass) {
    std::vector<Vec3> next = m.vertices;
    for (size_t v = 0; v < m.vertices.size(); ++v) {
      if (neighbors[v].empty()) continue;
      Vec3 mean{0, 0, 0};
      for (int w : neighbors[v]) mean += m.vertices[w];
      mean = mean / static_cast<double>(neighbors[v].size());
      next[v] = 0.5 * (m.vertices[v] + mean);
    }
    m.vertices = std::move(next);
  }
  return m;
}

namespace {

double torus_distance(Vec3 p, Vec3 center, double R, double r) {
  Vec3 q = p - center;
  double ring = std::hypot(q.x, q.y) - R;
  return std::hypot(ring, q.z) - r;
}

double box_distance(Vec3 p, Vec3 half) {
  Vec3 q{std::fabs(p.x) - half.x, std::fabs(p.y) - half.y, std::fabs(p.z) - half.z};
  Vec3 outside{std::max(q.x, 0.0), std::max(q.y, 0.0), std::max(q.z, 0.0)};
  return norm(outside) + std::min(std::max({q.x, q.y, q.z}), 0.0);
}

// Marching tetrahedra makes about 7.8 faces per (surface area / h^2); this
// picks the grid for a requested face count from an area estimate.
int cells_for(double area, double longest_side, int triangles) {
  double h = std::sqrt(7.8 * area / std::max(triangles, 100));
  return std::max(8, static_cast<int>(longest_side / h));
}

}  // namespace

TriMesh fused_tori(int genus, int triangles) {
  const double R = 1.0, r = 0.4, spacing = 1.7;
  auto f = [=](Vec3 p) {
    double d = INFINITY;
    for (int g = 0; g < genus; ++g) d = std::min(d, torus_distance(p, {g * spacing, 0, 0}, R, r));
    return d;
  };
  double width = (genus - 1) * spacing + 2 * (R + r) + 0.2;
  Vec3 lo{-(R + r) - 0.1, -(R + r) - 0.1, -r - 0.1};
  Vec3 hi{lo.x + width, R + r + 0.1, r + 0.1};
  double area = genus * 4 * M_PI * M_PI * R * r * 0.9;
  return march(f, lo, hi, cells_for(area, width, triangles), 3);
}

TriMesh drilled_block(int triangles) {
  auto f = [](Vec3 p) {
    double block = box_distance(p, {1.0, 0.7, 0.4});
    double hole = 0.3 - std::hypot(p.x + 0.4, p.y);  // vertical hole, negative outside the drill
    double boss_side = std::hypot(p.x - 0.5, p.y) - 0.3;
    double boss = std::max(boss_side, std::fabs(p.z - 0.5) - 0.2);
    return std::min(std::max(block, hole), boss);
  };
  Vec3 lo{-1.1, -0.8, -0.5}, hi{1.1, 0.8, 0.8};
  double area = 2 * (2 * 1.4 + 2 * 0.8 + 1.4 * 0.8) + 2 * M_PI * 0.3 * 0.8 + 2 * M_PI * 0.3 * 0.2;
  return march(f, lo, hi, cells_for(area, 2.2, triangles), 1);
}

}  // namespace soupuv::test_meshes
