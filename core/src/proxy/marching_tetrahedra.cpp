// Marching tetrahedra over the Kuhn subdivision of the narrow band's cells.
// See soupuv/proxy/marching_tetrahedra.h.
#include "soupuv/proxy/marching_tetrahedra.h"

#include <algorithm>
#include <array>
#include <utility>


#include "mesh_band_cells.h"

namespace soupuv::proxy {
namespace {

// Keeps vertices off the grid corners (see the header).
constexpr double kEdgeMargin = 1e-3;

// The six Kuhn tetrahedra of the unit cube: corner 0 -> +e_a -> +e_b -> corner 7,
// for each permutation (a, b, c) of the axes; `positive` is the permutation's
// sign, which is the sign of the tetrahedron's volume.
struct KuhnTet {
  std::array<int, 4> corner;  // bit mask x | y<<1 | z<<2
  bool positive;
};
constexpr std::array<KuhnTet, 6> kTets = {{
    {{0, 1, 3, 7}, true},   // x y z
    {{0, 2, 6, 7}, true},   // y z x
    {{0, 4, 5, 7}, true},   // z x y
    {{0, 1, 5, 7}, false},  // x z y
    {{0, 2, 3, 7}, false},  // y x z
    {{0, 4, 6, 7}, false},  // z y x
}};

bool even_permutation(const std::array<int, 4>& p) {
  int inversions = 0;
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j) inversions += p[i] > p[j];
  return inversions % 2 == 0;
}

struct Emitter {
  const NarrowBand& band;
  std::array<int, 3> cell;
  std::array<double, 8> f;
  std::vector<EdgeVertex>& vertices;
  std::vector<std::array<uint64_t, 3>>& triangles;

  // The vertex on the edge between cube corners a and b (one is inside).
  // Keyed by (lower corner, direction), so every cell sharing the edge
  // computes the same key and the same position.
  uint64_t edge_vertex(int a, int b) {
    if (a > b) std::swap(a, b);  // b - a is a 0/1 vector along a Kuhn path
    int dir = b - a;             // bit mask 1..7 (corners are bit masks too)
    std::array<int, 3> lo{cell[0] + (a & 1), cell[1] + ((a >> 1) & 1), cell[2] + (a >> 2)};
    uint64_t corner = grid_key(lo[0], lo[1], lo[2]);
    uint64_t key = (corner << 3) | uint64_t(dir);
    double t = std::clamp(f[a] / (f[a] - f[b]), kEdgeMargin, 1 - kEdgeMargin);
    Vec3 pa = band.corner_position(corner);
    Vec3 step{double(dir & 1), double((dir >> 1) & 1), double(dir >> 2)};
    vertices.push_back({key, pa + (t * band.cell) * step});
    return key;
  }

  void triangle(uint64_t a, uint64_t b, uint64_t c, bool flip) {
    if (flip) std::swap(b, c);
    triangles.push_back({a, b, c});
  }

  // Emits the level set inside one tetrahedron (corners as cube bit masks).
  void tet(const KuhnTet& t) {
    std::array<int, 4> in{}, out{};
    int n_in = 0, n_out = 0;
    for (int i = 0; i < 4; ++i) {
      if (f[t.corner[i]] < 0)
        in[n_in++] = i;
      else
        out[n_out++] = i;
    }
    if (n_in == 0 || n_in == 4) return;
    const auto& c = t.corner;
    // Reorder the tetrahedron to a canonical case; an odd reordering flips
    // its orientation, as does a negative Kuhn tetrahedron.
    if (n_in == 1 || n_in == 3) {
      int apex = n_in == 1 ? in[0] : out[0];
      std::array<int, 4> p{apex, 0, 0, 0};
      for (int i = 0, k = 1; i < 4; ++i)
        if (i != apex) p[k++] = i;
      bool flip = even_permutation(p) != t.positive;
      // Around a lone inside corner the normal points away from it; around a
      // lone outside corner, towards it.
      if (n_in == 3) flip = !flip;
      uint64_t a = edge_vertex(c[p[0]], c[p[1]]), b = edge_vertex(c[p[0]], c[p[2]]),
               d = edge_vertex(c[p[0]], c[p[3]]);
      triangle(a, b, d, flip);
      return;
    }
    std::array<int, 4> p{in[0], in[1], out[0], out[1]};
    bool flip = even_permutation(p) != t.positive;
    // Quad around the inside edge, then split along its shorter diagonal.
    uint64_t q[4] = {edge_vertex(c[p[0]], c[p[2]]), edge_vertex(c[p[0]], c[p[3]]),
                     edge_vertex(c[p[1]], c[p[3]]), edge_vertex(c[p[1]], c[p[2]])};
    size_t n = vertices.size();
    Vec3 v0 = vertices[n - 4].position, v1 = vertices[n - 3].position,
         v2 = vertices[n - 2].position, v3 = vertices[n - 1].position;
    if (norm2(v0 - v2) <= norm2(v1 - v3)) {
      triangle(q[0], q[1], q[2], flip);
      triangle(q[0], q[2], q[3], flip);
    } else {
      triangle(q[0], q[1], q[3], flip);
      triangle(q[1], q[2], q[3], flip);
    }
  }
};

}  // namespace

TriMesh marching_tetrahedra(const NarrowBand& band, Progress& progress) {
  return mesh_band_cells(
      band, "proxy: marching tetrahedra", progress,
      [&band](std::vector<EdgeVertex>& vertices, std::vector<std::array<uint64_t, 3>>& triangles) {
        return [&band, &vertices, &triangles](size_t n) {
          auto cell = grid_coords(band.cells[n]);
          std::array<double, 8> f = band.cell_values(n);
          int inside = 0;
          for (int v = 0; v < 8; ++v) inside += f[v] < 0;
          if (inside == 0 || inside == 8) return;
          Emitter emit{band, cell, f, vertices, triangles};
          for (const KuhnTet& t : kTets) emit.tet(t);
        };
      });
}

}  // namespace soupuv::proxy
