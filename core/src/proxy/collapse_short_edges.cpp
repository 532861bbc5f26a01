// Shortest-first edge collapse with link-condition, flip and length checks,
// in parallel by spatial slabs. See soupuv/proxy/collapse_short_edges.h.
#include "soupuv/proxy/collapse_short_edges.h"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace soupuv::proxy {
namespace {

// Per-thread scratch and counters. `mark` (one entry per vertex) with a
// fresh `stamp` per use marks a one-ring without sorting or clearing.
struct Worker {
  std::vector<uint32_t> mark;
  uint32_t stamp = 0;
  CollapseStats stats;
};

class Collapser {
 public:
  Collapser(const TriMesh& mesh, double max_len)
      : p_(mesh.vertices), f_(mesh.faces), face_alive_(mesh.faces.size(), 1),
        vertex_alive_(mesh.vertices.size(), 1), vf_(mesh.vertices.size()),
        slab_(mesh.vertices.size(), 0), max2_(max_len * max_len) {
    for (int f = 0; f < int(f_.size()); ++f)
      for (int v : f_[f]) vf_[v].push_back(f);
  }

  // Labels every vertex with its slab along the mesh's longest axis: `count`
  // slabs, shifted by `shift` (a fraction of a slab) so a second phase has
  // its slab interiors where the first had its boundaries.
  void assign_slabs(int count, double shift) {
    Box3 box;
    for (const Vec3& p : p_) box.add(p);
    Vec3 ext = box.extent();
    int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
    double width = ext[axis] / count;
    for (size_t v = 0; v < p_.size(); ++v) {
      double t = width > 0 ? (p_[v][axis] - box.lo[axis]) / width + shift : 0;
      slab_[v] = std::clamp(int(std::floor(t)), 0, count);
    }
    slab_faces_.assign(size_t(count) + 1, {});
    for (size_t f = 0; f < f_.size(); ++f)
      if (face_alive_[f]) slab_faces_[size_t(slab_[f_[f][0]])].push_back(int(f));
  }

  // One sweep over `faces` (in face order: spatially coherent, cache
  // friendly): every edge shorter than `length` is tried once. Shortest-
  // first is approximated by sweeping with a slowly growing threshold (see
  // collapse_short_edges), which avoids a global heap of millions of edges.
  // slab >= 0: only collapses whose whole neighbourhood lies in that slab,
  // so threads on different slabs never touch the same face or vertex list.
  size_t sweep(const std::vector<int>& faces, double length, int slab, Worker& w) {
    const double limit2 = length * length;
    size_t before = w.stats.collapses;
    for (int f : faces)
      for (int k = 0; k < 3 && face_alive_[size_t(f)]; ++k) {
        int u = f_[size_t(f)][k], v = f_[size_t(f)][(k + 1) % 3];
        // Another slab's vertex may be moving right now: not even read.
        if (slab >= 0 && (slab_[u] != slab || slab_[v] != slab)) continue;
        if (norm2(p_[u] - p_[v]) < limit2) collapse(u, v, slab, w);
      }
    return w.stats.collapses - before;
  }

  // The threshold schedule of one region: thresholds growing by 1.25 from
  // min_len / 16 up to min_len (short edges go first, as with a heap), then
  // extra sweeps at min_len for edges refused early (a neighbour in the way)
  // that pass once their neighbourhood has been coarsened.
  void schedule(const std::vector<int>& faces, double min_len, int slab, Worker& w) {
    for (double length = min_len / 16; length < min_len; length *= 1.25) sweep(faces, length, slab, w);
    for (int pass = 0; pass < 4; ++pass)
      if (sweep(faces, min_len, slab, w) < faces.size() / 500 + 1) break;
  }

  // Every slab on its own, in parallel.
  void parallel_phase(int slabs, double shift, double min_len, std::vector<Worker>& workers) {
    assign_slabs(slabs, shift);
#pragma omp parallel for schedule(dynamic, 1)
    for (int s = 0; s <= slabs; ++s) schedule(slab_faces_[size_t(s)], min_len, s, workers[size_t(omp_get_thread_num())]);
  }

  std::vector<int> alive_faces() const {
    std::vector<int> out;
    for (size_t f = 0; f < f_.size(); ++f)
      if (face_alive_[f]) out.push_back(int(f));
    return out;
  }

  TriMesh result() const {
    TriMesh out;
    std::vector<int> index(p_.size(), -1);
    for (size_t v = 0; v < p_.size(); ++v)
      if (vertex_alive_[v] && !vf_[v].empty()) {
        index[v] = int(out.vertices.size());
        out.vertices.push_back(p_[v]);
      }
    for (size_t f = 0; f < f_.size(); ++f)
      if (face_alive_[f]) out.faces.push_back({index[f_[f][0]], index[f_[f][1]], index[f_[f][2]]});
    return out;
  }

 private:
  static bool has(const std::array<int, 3>& t, int v) { return t[0] == v || t[1] == v || t[2] == v; }

  Vec3 normal(const std::array<int, 3>& t, int from, int to, Vec3 moved) const {
    auto at = [&](int v) { return v == from || v == to ? moved : p_[v]; };
    return cross(at(t[1]) - at(t[0]), at(t[2]) - at(t[0]));
  }

  void collapse(int a, int b, int slab, Worker& w) {
    // The two faces on edge ab and their opposite vertices.
    int shared[2], n_shared = 0;
    for (int f : vf_[a])
      if (has(f_[f], b)) {
        if (n_shared == 2) return;  // not manifold here: leave it alone
        shared[n_shared++] = f;
      }
    if (n_shared != 2) return;
    // In a slab phase the whole neighbourhood must be this slab's: every
    // face touched below has its corners among a, b and their rings.
    if (slab >= 0)
      for (int end : {a, b})
        for (int f : vf_[end])
          for (int v : f_[f])
            if (slab_[v] != slab) return;
    int opposite[2];
    for (int s = 0; s < 2; ++s)
      for (int v : f_[shared[s]])
        if (v != a && v != b) opposite[s] = v;
    // Link condition: the rings of a and b meet only in the two opposite
    // vertices; a valence-3 opposite vertex would be left with two faces.
    const uint32_t in_ring_a = ++w.stamp, counted = ++w.stamp;
    for (int f : vf_[a])
      for (int v : f_[f])
        if (v != a) w.mark[size_t(v)] = in_ring_a;
    int common = 0;
    for (int f : vf_[b])
      for (int v : f_[f])
        if (v != b && w.mark[size_t(v)] == in_ring_a) {
          w.mark[size_t(v)] = counted;
          ++common;
        }
    if (common != 2 || opposite[0] == opposite[1] || vf_[opposite[0]].size() <= 3 ||
        vf_[opposite[1]].size() <= 3) {
      ++w.stats.refused_link;
      return;
    }
    const Vec3 mid = 0.5 * (p_[a] + p_[b]);
    for (int end : {a, b})
      for (int f : vf_[end])
        for (int v : f_[f])
          if (v != a && v != b && norm2(p_[v] - mid) > max2_) {
            ++w.stats.refused_long;
            return;
          }
    // No face may turn by more than ~80 degrees or become degenerate.
    for (int v : {a, b})
      for (int f : vf_[v]) {
        if (f == shared[0] || f == shared[1]) continue;
        Vec3 before = normal(f_[f], -1, -1, mid), after = normal(f_[f], a, b, mid);
        double nb = norm2(before), na = norm2(after);
        if (!(na > 1e-24 * max2_ * max2_) || dot(before, after) <= 0.2 * std::sqrt(na * nb)) {
          ++w.stats.refused_flip;
          return;
        }
      }

    for (int s = 0; s < 2; ++s) {
      face_alive_[shared[s]] = 0;
      for (int v : {a, b, opposite[0], opposite[1]}) {
        auto& list = vf_[v];
        list.erase(std::remove(list.begin(), list.end(), shared[s]), list.end());
      }
    }
    for (int f : vf_[b]) {
      for (int& v : f_[f])
        if (v == b) v = a;
      vf_[a].push_back(f);
    }
    std::vector<int>().swap(vf_[b]);
    vertex_alive_[b] = 0;
    p_[a] = mid;
    ++w.stats.collapses;
  }

  std::vector<Vec3> p_;
  std::vector<std::array<int, 3>> f_;
  std::vector<char> face_alive_, vertex_alive_;
  std::vector<std::vector<int>> vf_;  // faces around each vertex
  std::vector<int> slab_;             // per vertex, for the parallel phases
  std::vector<std::vector<int>> slab_faces_;
  double max2_;
};

}  // namespace

TriMesh collapse_short_edges(const TriMesh& mesh, double min_edge_length, double max_edge_length,
                             CollapseStats* stats) {
  if (!(min_edge_length > 0) || mesh.faces.empty()) return mesh;
  Collapser collapser(mesh, std::max(min_edge_length, max_edge_length));
  std::vector<Worker> workers(static_cast<size_t>(omp_get_max_threads()));
  for (Worker& w : workers) w.mark.assign(mesh.vertices.size(), 0);
  // Two parallel phases on 8 slabs, the second shifted by half a slab so the
  // first one's boundary strips (left alone there) are slab interiors; then
  // one serial schedule over everything for what is left. The slab count is
  // fixed, not the thread count, so the result does not depend on threads.
  constexpr int kSlabs = 8;
  collapser.parallel_phase(kSlabs, 0.0, min_edge_length, workers);
  collapser.parallel_phase(kSlabs, 0.5, min_edge_length, workers);
  collapser.schedule(collapser.alive_faces(), min_edge_length, -1, workers[0]);
  if (stats) {
    *stats = {};
    for (const Worker& w : workers) {
      stats->collapses += w.stats.collapses;
      stats->refused_link += w.stats.refused_link;
      stats->refused_flip += w.stats.refused_flip;
      stats->refused_long += w.stats.refused_long;
    }
  }
  return collapser.result();
}

}  // namespace soupuv::proxy
