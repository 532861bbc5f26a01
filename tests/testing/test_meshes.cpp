#include "testing/test_meshes.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>

namespace soupuv::test_meshes {

TriMesh march(const std::function<double(Vec3)>& f, Vec3 lo, Vec3 hi, int cells, int smoothing) {
  Vec3 ext = hi - lo;
  double h = std::max({ext.x, ext.y, ext.z}) / cells;
  const int nx = static_cast<int>(std::ceil(ext.x / h)) + 1;
  const int ny = static_cast<int>(std::ceil(ext.y / h)) + 1;
  const int nz = static_cast<int>(std::ceil(ext.z / h)) + 1;
  auto id = [&](int i, int j, int k) { return (static_cast<long long>(k) * ny + j) * nx + i; };
  auto point = [&](long long v) {
    int i = static_cast<int>(v % nx), j = static_cast<int>((v / nx) % ny), k = static_cast<int>(v / (static_cast<long long>(nx) * ny));
    return Vec3{lo.x + i * h, lo.y + j * h, lo.z + k * h};
  };
  std::vector<double> value(static_cast<size_t>(nx) * ny * nz);
  for (long long v = 0; v < static_cast<long long>(value.size()); ++v) {
    double x = f(point(v));
    // A sample exactly on the surface would make a degenerate triangle.
    value[v] = std::fabs(x) < 1e-9 ? 1e-9 : x;
  }

  TriMesh m;
  std::unordered_map<long long, int> edge_vertex;
  auto vertex_on = [&](long long a, long long b) {
    if (a > b) std::swap(a, b);
    long long key = a * static_cast<long long>(value.size()) + b;
    auto it = edge_vertex.find(key);
    if (it != edge_vertex.end()) return it->second;
    double t = value[a] / (value[a] - value[b]);
    int idx = static_cast<int>(m.vertices.size());
    m.vertices.push_back(point(a) + t * (point(b) - point(a)));
    edge_vertex.emplace(key, idx);
    return idx;
  };
  // Six tetrahedra around the cube diagonal 0-7 (corner bits: x=1, y=2, z=4);
  // the same split in every cube keeps the surface watertight.
  static const int tets[6][4] = {{0, 1, 3, 7}, {0, 3, 2, 7}, {0, 2, 6, 7},
                                 {0, 6, 4, 7}, {0, 4, 5, 7}, {0, 5, 1, 7}};
  auto emit = [&](int a, int b, int c, Vec3 outward) {
    Vec3 n = cross(m.vertices[b] - m.vertices[a], m.vertices[c] - m.vertices[a]);
    if (dot(n, outward) < 0) std::swap(b, c);
    m.faces.push_back({a, b, c});
  };
  for (int k = 0; k + 1 < nz; ++k)
    for (int j = 0; j + 1 < ny; ++j)
      for (int i = 0; i + 1 < nx; ++i) {
        long long corner[8];
        for (int c = 0; c < 8; ++c) corner[c] = id(i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1));
        for (const auto& tet : tets) {
          std::vector<long long> in, out;
          for (int c : tet) (value[corner[c]] < 0 ? in : out).push_back(corner[c]);
          if (in.empty() || out.empty()) continue;
          Vec3 ci{0, 0, 0}, co{0, 0, 0};
          for (long long v : in) ci += point(v) / static_cast<double>(in.size());
          for (long long v : out) co += point(v) / static_cast<double>(out.size());
          Vec3 outward = co - ci;
          if (in.size() == 1 || out.size() == 1) {
            long long apex = in.size() == 1 ? in[0] : out[0];
            const auto& rest = in.size() == 1 ? out : in;
            emit(vertex_on(apex, rest[0]), vertex_on(apex, rest[1]), vertex_on(apex, rest[2]), outward);
          } else {
            int a = vertex_on(in[0], out[0]), b = vertex_on(in[0], out[1]);
            int c = vertex_on(in[1], out[1]), d = vertex_on(in[1], out[0]);
            emit(a, b, c, outward);
            emit(a, c, d, outward);
          }
        }
      }

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
