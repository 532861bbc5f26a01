// Closed / oriented / manifold / Euler checks by sorting half-edges.
// See soupuv/proxy/mesh_checks.h.
#include "soupuv/proxy/mesh_checks.h"

#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

namespace soupuv::proxy {

Topology check_topology(const TriMesh& mesh) {
  Topology topo;
  topo.faces = long(mesh.faces.size());
  const size_t nv = mesh.vertices.size();
  std::vector<std::pair<uint64_t, uint32_t>> half;  // (from << 32 | to, face)
  half.reserve(mesh.faces.size() * 3);
  std::vector<char> used(nv, 0);
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    const auto& t = mesh.faces[f];
    for (int k = 0; k < 3; ++k) {
      used[t[k]] = 1;
      half.push_back({(uint64_t(t[k]) << 32) | uint32_t(t[(k + 1) % 3]), uint32_t(f)});
    }
    Vec3 a = mesh.vertices[t[0]], b = mesh.vertices[t[1]], c = mesh.vertices[t[2]];
    if (!(norm2(cross(b - a, c - a)) > 0)) ++topo.degenerate_faces;
  }
  for (char u : used) topo.vertices += u;
  std::sort(half.begin(), half.end());

  // Undirected edges with their multiplicity.
  std::vector<uint64_t> undirected;
  undirected.reserve(half.size());
  bool oriented = true;
  for (size_t i = 0; i < half.size(); ++i) {
    if (i > 0 && half[i].first == half[i - 1].first) oriented = false;  // directed edge twice
    uint64_t from = half[i].first >> 32, to = half[i].first & 0xffffffffu;
    undirected.push_back(from < to ? half[i].first : (to << 32) | from);
    uint64_t twin = (to << 32) | from;
    if (!std::binary_search(half.begin(), half.end(), std::make_pair(twin, uint32_t(0)),
                            [](const auto& a, const auto& b) { return a.first < b.first; }))
      oriented = false;
  }
  std::sort(undirected.begin(), undirected.end());
  bool closed = true;
  for (size_t i = 0; i < undirected.size();) {
    size_t j = i;
    while (j < undirected.size() && undirected[j] == undirected[i]) ++j;
    if (j - i != 2) closed = false;
    ++topo.edges;
    i = j;
  }
  topo.closed = closed && !mesh.faces.empty();
  topo.oriented = oriented && topo.closed;

  // One fan per vertex: around v, face (v, b, c) leads to the face whose
  // corner after v... i.e. the face (v, c', b') with c' == b is the neighbour
  // across edge (v, b). Walk from one face; the walk must visit all of v's faces.
  bool manifold = topo.oriented;
  if (manifold) {
    std::vector<uint32_t> start(nv + 1, 0);
    for (const auto& t : mesh.faces)
      for (int k = 0; k < 3; ++k) ++start[t[k] + 1];
    for (size_t v = 0; v < nv; ++v) start[v + 1] += start[v];
    std::vector<std::pair<int, int>> fan(start[nv]);  // (next corner, previous corner) around v
    std::vector<uint32_t> fill(start.begin(), start.end() - 1);
    for (const auto& t : mesh.faces)
      for (int k = 0; k < 3; ++k) fan[fill[t[k]]++] = {t[(k + 1) % 3], t[(k + 2) % 3]};
    for (size_t v = 0; v < nv && manifold; ++v) {
      uint32_t b = start[v], e = start[v + 1];
      if (b == e) continue;
      // Sort this vertex's faces by their previous corner to find successors.
      std::sort(fan.begin() + b, fan.begin() + e,
                [](const auto& x, const auto& y) { return x.second < y.second; });
      int first_next = fan[b].first;
      int current_next = first_next;
      uint32_t steps = 0;
      do {
        auto it = std::lower_bound(fan.begin() + b, fan.begin() + e, current_next,
                                   [](const auto& x, int key) { return x.second < key; });
        if (it == fan.begin() + e || it->second != current_next) {
          manifold = false;
          break;
        }
        current_next = it->first;
        ++steps;
      } while (current_next != first_next && steps <= e - b);
      if (steps != e - b) manifold = false;
    }
  }
  topo.manifold = manifold;
  return topo;
}

}  // namespace soupuv::proxy
