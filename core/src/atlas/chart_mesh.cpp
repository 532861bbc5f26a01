#include "atlas/chart_mesh.h"

#include "soupuv/union_find.h"

namespace soupuv::atlas {

ChartMesh extract_chart(const TriMesh& mesh, const MeshTopology& t, const std::vector<int>& faces,
                        const std::vector<int>& face_chart, const std::vector<char>& seam,
                        std::vector<int>& face_local) {
  ChartMesh c;
  c.faces = faces;
  const int n = static_cast<int>(faces.size());
  const int chart = face_chart[faces[0]];
  for (int i = 0; i < n; ++i) face_local[faces[i]] = i;
  auto inside = [&](int f, int k) {
    int g = t.face_neighbor[f][k];
    return face_chart[g] == chart && !seam[t.face_edge[f][k]];
  };

  // Corners 3*i+k; corners that meet across an interior edge are one vertex.
  UnionFind corners(3 * size_t(n));
  int boundary_half_edges = 0;
  for (int i = 0; i < n; ++i) {
    int f = faces[i];
    for (int k = 0; k < 3; ++k) {
      if (!inside(f, k)) { ++boundary_half_edges; continue; }
      int g = t.face_neighbor[f][k];
      int j = face_local[g];
      if (j < i) continue;
      int kk = 0;
      while (t.face_edge[g][kk] != t.face_edge[f][k]) ++kk;
      // Edge k of f runs a->b; the same edge in g runs b->a.
      corners.unite(3 * i + k, 3 * j + (kk + 1) % 3);
      corners.unite(3 * i + (k + 1) % 3, 3 * j + kk);
    }
  }
  std::vector<int> local_of_root(3 * n, -1);
  c.tri.resize(n);
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) {
      const uint32_t r = corners.find(3 * i + k);
      if (local_of_root[r] < 0) {
        local_of_root[r] = static_cast<int>(c.vertex_global.size());
        int v = mesh.faces[faces[i]][k];
        c.vertex_global.push_back(v);
        c.position.push_back(mesh.vertices[v]);
      }
      c.tri[i][k] = local_of_root[r];
    }

  const int nv = static_cast<int>(c.vertex_global.size());
  const int edges = (3 * n + boundary_half_edges) / 2;
  c.euler = nv - edges + n;

  // Each boundary vertex of a corner-split chart has exactly one outgoing
  // boundary half-edge, so the loops are cycles of next_on_boundary.
  std::vector<int> next_on_boundary(nv, -1);
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k)
      if (!inside(faces[i], k)) next_on_boundary[c.tri[i][k]] = c.tri[i][(k + 1) % 3];
  std::vector<char> visited(nv, 0);
  int boundary_vertices = 0;
  for (int v = 0; v < nv; ++v) boundary_vertices += next_on_boundary[v] >= 0;
  for (int v = 0; v < nv; ++v) {
    if (next_on_boundary[v] < 0 || visited[v]) continue;
    ++c.boundary_loops;
    int w = v, guard = 0;
    std::vector<int> loop;
    while (!visited[w] && w >= 0 && guard++ <= nv) {
      visited[w] = 1;
      loop.push_back(w);
      w = next_on_boundary[w];
    }
    if (c.boundary_loops == 1) c.boundary = std::move(loop);
  }
  // More boundary half-edges than boundary vertices means a vertex with two
  // outgoing boundary edges: not a manifold disk, whatever the counts say.
  if (boundary_vertices != boundary_half_edges) c.boundary_loops = -1;
  return c;
}

}  // namespace soupuv::atlas
