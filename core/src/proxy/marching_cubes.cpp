// Marching cubes by face segments and loops, asymptotic decider on faces.
// See soupuv/proxy/marching_cubes.h.
#include "soupuv/proxy/marching_cubes.h"

#include <algorithm>
#include <array>
#include <utility>


#include "mesh_band_cells.h"
#include "soupuv/errors.h"

namespace soupuv::proxy {
namespace {

// Keeps vertices off the grid corners (see the header).
constexpr double kEdgeMargin = 1e-3;
// Loop centroids get keys of their own, apart from the edge-vertex keys.
constexpr uint64_t kCentroidBit = uint64_t{1} << 63;

// Cube corners are bit masks x | y<<1 | z<<2. Each face lists its corners
// counter-clockwise seen from outside the cube: (c1 - c0) x (c3 - c0) is the
// face's outward normal.
constexpr int kFaces[6][4] = {
    {0, 4, 6, 2},  // x = 0
    {1, 3, 7, 5},  // x = 1
    {0, 1, 5, 4},  // y = 0
    {2, 6, 7, 3},  // y = 1
    {0, 2, 3, 1},  // z = 0
    {4, 5, 7, 6},  // z = 1
};

// Local id of the cube edge between corners a and b (one bit apart):
// lower corner * 3 + axis, so 0 .. 23 (only 12 of them are used).
int local_edge(int a, int b) {
  int lo = std::min(a, b), axis = (a ^ b) == 1 ? 0 : ((a ^ b) == 2 ? 1 : 2);
  return lo * 3 + axis;
}

struct CellMesher {
  const NarrowBand& band;
  std::vector<EdgeVertex>& vertices;
  std::vector<std::array<uint64_t, 3>>& triangles;
  std::array<int, 3> cell{};
  std::array<double, 8> f{};
  std::array<int, 24> next{};  // directed segments: next[from] = to

  bool inside(int corner) const { return f[corner] < 0; }

  void segment(int from, int to) {
    if (next[from] != -1) throw Error(ErrorCode::internal, "marching cubes: inconsistent face segments");
    next[from] = to;
  }

  // Segments on one face; inside corners lie to the left of each segment seen
  // from outside the cube (so loops run counter-clockwise around the inside).
  void face(const int (&c)[4]) {
    int n_in = 0;
    for (int i = 0; i < 4; ++i) n_in += inside(c[i]);
    if (n_in == 0 || n_in == 4) return;
    auto e = [&](int i, int j) { return local_edge(c[(i + 4) % 4], c[(j + 4) % 4]); };
    auto around_inside = [&](int i) { segment(e(i - 1, i), e(i, i + 1)); };
    auto around_outside = [&](int j) { segment(e(j, j + 1), e(j - 1, j)); };
    if (n_in == 1) {
      for (int i = 0; i < 4; ++i)
        if (inside(c[i])) around_inside(i);
    } else if (n_in == 3) {
      for (int j = 0; j < 4; ++j)
        if (!inside(c[j])) around_outside(j);
    } else {
      for (int i = 0; i < 4; ++i) {
        if (inside(c[i]) && inside(c[(i + 1) % 4])) {  // adjacent pair
          segment(e(i - 1, i), e(i + 1, i + 2));
          return;
        }
      }
      // Opposite pair: asymptotic decider. The bilinear saddle value is
      // (fi fk - fj fl) / (fi + fk - fj - fl) with i, k inside; the
      // denominator is negative, so the saddle is inside exactly when
      // fi fk > fj fl — products, hence independent of the corner order in
      // which the two cells sharing this face list it.
      int i = inside(c[0]) ? 0 : 1;
      bool joined = f[c[i]] * f[c[i + 2]] > f[c[i + 1]] * f[c[(i + 3) % 4]];
      if (joined) {
        around_outside(i + 1);
        around_outside((i + 3) % 4);
      } else {
        around_inside(i);
        around_inside(i + 2);
      }
    }
  }

  uint64_t edge_vertex(int local) {
    int lo = local / 3, axis = local % 3;
    int hi = lo | (1 << axis);
    uint64_t corner = grid_key(cell[0] + (lo & 1), cell[1] + ((lo >> 1) & 1), cell[2] + (lo >> 2));
    uint64_t key = (corner << 2) | uint64_t(axis);
    double t = std::clamp(f[lo] / (f[lo] - f[hi]), kEdgeMargin, 1 - kEdgeMargin);
    Vec3 position = band.corner_position(corner);
    position[axis] += t * band.cell;
    vertices.push_back({key, position});
    return key;
  }

  void run(size_t n) {
    const uint64_t cell_key = band.cells[n];
    cell = grid_coords(cell_key);
    f = band.cell_values(n);
    next.fill(-1);
    for (const auto& c : kFaces) face(c);
    int loop_index = 0;
    for (int start = 0; start < 24; ++start) {
      if (next[start] == -1) continue;
      // Follow the loop, consuming its segments.
      std::array<uint64_t, 12> loop;
      std::array<Vec3, 12> at;
      int n = 0, e = start;
      while (next[e] != -1) {
        if (n == 12) throw Error(ErrorCode::internal, "marching cubes: loop longer than 12");
        loop[n] = edge_vertex(e);
        at[n++] = vertices.back().position;
        int to = next[e];
        next[e] = -1;
        e = to;
      }
      if (n < 3 || e != start) throw Error(ErrorCode::internal, "marching cubes: open loop");
      if (n == 3) {
        triangles.push_back({loop[0], loop[1], loop[2]});
      } else if (n == 4) {
        if (norm2(at[0] - at[2]) <= norm2(at[1] - at[3])) {
          triangles.push_back({loop[0], loop[1], loop[2]});
          triangles.push_back({loop[0], loop[2], loop[3]});
        } else {
          triangles.push_back({loop[0], loop[1], loop[3]});
          triangles.push_back({loop[1], loop[2], loop[3]});
        }
      } else {
        Vec3 centroid{0, 0, 0};
        for (int k = 0; k < n; ++k) centroid += at[k];
        uint64_t key = kCentroidBit | (cell_key << 2) | uint64_t(loop_index);
        vertices.push_back({key, centroid / double(n)});
        for (int k = 0; k < n; ++k) triangles.push_back({key, loop[k], loop[(k + 1) % n]});
      }
      ++loop_index;
    }
  }
};

}  // namespace

TriMesh marching_cubes(const NarrowBand& band, Progress& progress) {
  return mesh_band_cells(band, "proxy: marching cubes", progress,
                         [&band](std::vector<EdgeVertex>& vertices, std::vector<std::array<uint64_t, 3>>& triangles) {
                           return [mesher = CellMesher{band, vertices, triangles}](size_t n) mutable { mesher.run(n); };
                         });
}

}  // namespace soupuv::proxy
