#include "testing/shapes.h"

#include <cmath>
#include <map>
#include <random>

namespace soupuv::shapes {

namespace {
constexpr double kPi = 3.14159265358979323846;

// Appends the two triangles of quad (a, b, c, d) given counter-clockwise.
void quad(TriMesh& m, int a, int b, int c, int d) {
  m.faces.push_back({a, b, c});
  m.faces.push_back({a, c, d});
}
}  // namespace

TriMesh uv_sphere(double radius, int rings, int segments) {
  TriMesh m;
  m.vertices.push_back({0, 0, radius});  // north pole
  for (int i = 1; i < rings; ++i) {
    double th = kPi * i / rings;
    for (int j = 0; j < segments; ++j) {
      double ph = 2 * kPi * j / segments;
      m.vertices.push_back({radius * std::sin(th) * std::cos(ph),
                            radius * std::sin(th) * std::sin(ph), radius * std::cos(th)});
    }
  }
  int south = static_cast<int>(m.vertices.size());
  m.vertices.push_back({0, 0, -radius});
  auto at = [&](int ring, int seg) { return 1 + (ring - 1) * segments + (seg % segments); };
  for (int j = 0; j < segments; ++j) m.faces.push_back({0, at(1, j), at(1, j + 1)});
  for (int i = 1; i < rings - 1; ++i)
    for (int j = 0; j < segments; ++j) quad(m, at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
  for (int j = 0; j < segments; ++j) m.faces.push_back({south, at(rings - 1, j + 1), at(rings - 1, j)});
  return m;
}

TriMesh icosphere(double radius, int level) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  TriMesh m;
  m.vertices = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  m.faces = {{0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
             {11, 10, 2}, {10, 7, 6}, {7, 1, 8}, {3, 9, 4}, {3, 4, 2}, {3, 2, 6}, {3, 6, 8},
             {3, 8, 9}, {4, 9, 5}, {2, 4, 11}, {6, 2, 10}, {8, 6, 7}, {9, 8, 1}};
  for (int l = 0; l < level; ++l) {
    std::vector<std::array<int, 3>> faces;
    std::vector<std::pair<std::pair<int, int>, int>> mid;  // small maps are fine here
    std::vector<std::vector<std::pair<int, int>>> adj(m.vertices.size());
    auto midpoint = [&](int a, int b) {
      if (a > b) std::swap(a, b);
      for (auto [other, idx] : adj[a])
        if (other == b) return idx;
      int idx = static_cast<int>(m.vertices.size());
      m.vertices.push_back(0.5 * (m.vertices[a] + m.vertices[b]));
      adj[a].push_back({b, idx});
      adj.emplace_back();
      return idx;
    };
    for (auto f : m.faces) {
      int a = midpoint(f[0], f[1]), b = midpoint(f[1], f[2]), c = midpoint(f[2], f[0]);
      faces.push_back({f[0], a, c});
      faces.push_back({f[1], b, a});
      faces.push_back({f[2], c, b});
      faces.push_back({a, b, c});
    }
    m.faces = std::move(faces);
  }
  for (Vec3& v : m.vertices) v = radius * normalized(v);
  return m;
}

TriMesh sphere_with(double radius, int triangles) {
  // 2*segments*(rings-1) triangles with segments = 2*rings for square-ish cells.
  int rings = std::max(3, static_cast<int>(std::lround(std::sqrt(triangles / 4.0))));
  return uv_sphere(radius, rings, 2 * rings);
}

TriMesh torus(double R, double r, int n, int m) {
  TriMesh mesh;
  for (int i = 0; i < n; ++i) {
    double u = 2 * kPi * i / n;
    for (int j = 0; j < m; ++j) {
      double v = 2 * kPi * j / m;
      mesh.vertices.push_back({(R + r * std::cos(v)) * std::cos(u),
                               (R + r * std::cos(v)) * std::sin(u), r * std::sin(v)});
    }
  }
  auto at = [&](int i, int j) { return (i % n) * m + (j % m); };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < m; ++j) quad(mesh, at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
  return mesh;
}

TriMesh torus_with(double R, double r, int triangles) {
  // The paper's resolutions are 2*s*s (800, 3200, ..., 105,800) or 2*(2s)*s
  // (1600, 6400, ...): square grids, or twice as many steps around the major circle.
  int half = std::max(1, triangles / 2);
  int s = static_cast<int>(std::lround(std::sqrt(double(half))));
  if (s * s == half) return torus(R, r, std::max(s, 3), std::max(s, 3));
  int m = std::max(3, static_cast<int>(std::lround(std::sqrt(half / 2.0))));
  return torus(R, r, 2 * m, m);
}

TriMesh plane_grid(Vec3 origin, Vec3 u, Vec3 v, int n) {
  TriMesh m;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) m.vertices.push_back(origin + u * (2.0 * i / n - 1) + v * (2.0 * j / n - 1));
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i;
      m.faces.push_back({a, a + 1, a + n + 2});
      m.faces.push_back({a, a + n + 2, a + n + 1});
    }
  return m;
}

TriMesh cube(double size, int n) {
  TriMesh m;
  double h = size / 2;
  // For each axis and sign, a grid on that face, oriented outward.
  for (int axis = 0; axis < 3; ++axis) {
    for (int sign = -1; sign <= 1; sign += 2) {
      int u = (axis + 1) % 3, v = (axis + 2) % 3;
      int base = static_cast<int>(m.vertices.size());
      for (int i = 0; i <= n; ++i)
        for (int j = 0; j <= n; ++j) {
          Vec3 p;
          p[axis] = sign * h;
          p[u] = -h + size * i / n;
          p[v] = -h + size * j / n;
          m.vertices.push_back(p);
        }
      auto at = [&](int i, int j) { return base + i * (n + 1) + j; };
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
          // (u, v, axis) is right-handed, so (i,j)->(i+1,j)->(i+1,j+1) faces +axis.
          if (sign > 0) quad(m, at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
          else quad(m, at(i, j), at(i, j + 1), at(i + 1, j + 1), at(i + 1, j));
        }
    }
  }
  // Weld the shared edge vertices so the cube is one closed manifold. Grid
  // points are exact multiples of size/n, so rounding to the grid index is exact.
  std::map<std::array<long, 3>, int> index;
  std::vector<int> remap(m.vertices.size());
  std::vector<Vec3> unique;
  for (size_t i = 0; i < m.vertices.size(); ++i) {
    std::array<long, 3> key;
    for (int a = 0; a < 3; ++a) key[a] = std::lround((m.vertices[i][a] + h) * n / size);
    auto [it, inserted] = index.emplace(key, static_cast<int>(unique.size()));
    if (inserted) unique.push_back(m.vertices[i]);
    remap[i] = it->second;
  }
  for (auto& f : m.faces)
    for (int& v : f) v = remap[v];
  m.vertices = std::move(unique);
  return m;
}

TriMesh cylinder(double radius, double height, int segments, int stacks, int cap_rings) {
  TriMesh m;
  auto ring_point = [&](double rr, double z, int j) {
    double ph = 2 * kPi * j / segments;
    return Vec3{rr * std::cos(ph), rr * std::sin(ph), z};
  };
  // Rows from the bottom cap centre outward, up the side, then the top cap inward.
  std::vector<std::pair<double, double>> rows;  // (radius, z)
  for (int k = 1; k <= cap_rings; ++k) rows.push_back({radius * k / cap_rings, -height / 2});
  for (int k = 1; k <= stacks; ++k) rows.push_back({radius, -height / 2 + height * k / stacks});
  for (int k = cap_rings - 1; k >= 1; --k) rows.push_back({radius * k / cap_rings, height / 2});
  int bottom = 0;
  m.vertices.push_back({0, 0, -height / 2});
  for (auto [rr, z] : rows)
    for (int j = 0; j < segments; ++j) m.vertices.push_back(ring_point(rr, z, j));
  int top = static_cast<int>(m.vertices.size());
  m.vertices.push_back({0, 0, height / 2});
  auto at = [&](int row, int j) { return 1 + row * segments + (j % segments); };
  int nrows = static_cast<int>(rows.size());
  for (int j = 0; j < segments; ++j) m.faces.push_back({bottom, at(0, j + 1), at(0, j)});
  for (int r = 0; r + 1 < nrows; ++r)
    for (int j = 0; j < segments; ++j) quad(m, at(r, j), at(r, j + 1), at(r + 1, j + 1), at(r + 1, j));
  for (int j = 0; j < segments; ++j) m.faces.push_back({top, at(nrows - 1, j), at(nrows - 1, j + 1)});
  return m;
}

TriMesh pipe(double radius, double height, int segments, int stacks) {
  TriMesh m;
  for (int k = 0; k <= stacks; ++k)
    for (int j = 0; j < segments; ++j) {
      double ph = 2 * kPi * j / segments;
      m.vertices.push_back({radius * std::cos(ph), radius * std::sin(ph), -height / 2 + height * k / stacks});
    }
  auto at = [&](int k, int j) { return k * segments + (j % segments); };
  for (int k = 0; k < stacks; ++k)
    for (int j = 0; j < segments; ++j) quad(m, at(k, j), at(k, j + 1), at(k + 1, j + 1), at(k + 1, j));
  return m;
}

Soup to_soup(const TriMesh& mesh, double noise, unsigned seed) {
  Soup s;
  s.positions.reserve(mesh.faces.size() * 3);
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    uint32_t base = static_cast<uint32_t>(s.positions.size());
    for (int k = 0; k < 3; ++k) s.positions.push_back(mesh.vertices[mesh.faces[f][k]]);
    s.triangles.push_back({base, base + 1, base + 2});
    TriangleOrigin o;
    o.source_index = static_cast<uint32_t>(f);
    s.origins.push_back(o);
  }
  if (noise > 0) {
    double amp = noise * bounding_box(s).diagonal();
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-amp, amp);
    for (Vec3& p : s.positions) p += Vec3{u(rng), u(rng), u(rng)};
  }
  return s;
}

Soup merge(const Soup& a, const Soup& b) {
  Soup s = a;
  uint32_t base = static_cast<uint32_t>(a.positions.size());
  int32_t mesh_base = 0;
  for (const auto& o : a.origins) mesh_base = std::max(mesh_base, o.mesh + 1);
  s.positions.insert(s.positions.end(), b.positions.begin(), b.positions.end());
  for (size_t t = 0; t < b.triangles.size(); ++t) {
    const Tri& tri = b.triangles[t];
    s.triangles.push_back({tri[0] + base, tri[1] + base, tri[2] + base});
    TriangleOrigin o = b.origins[t];
    o.mesh += mesh_base;
    s.origins.push_back(o);
  }
  s.warnings.insert(s.warnings.end(), b.warnings.begin(), b.warnings.end());
  return s;
}

void translate(TriMesh& mesh, Vec3 offset) {
  for (Vec3& v : mesh.vertices) v += offset;
}

}  // namespace soupuv::shapes
