// Shortest-first edge collapse with link-condition, flip and length checks.
// See soupuv/proxy/collapse_short_edges.h.
#include "soupuv/proxy/collapse_short_edges.h"

#include <algorithm>
#include <vector>

namespace soupuv::proxy {
namespace {

class Collapser {
 public:
  Collapser(const TriMesh& mesh, double max_len, CollapseStats& stats)
      : p_(mesh.vertices), f_(mesh.faces), face_alive_(mesh.faces.size(), 1),
        vertex_alive_(mesh.vertices.size(), 1), vf_(mesh.vertices.size()),
        max2_(max_len * max_len), stats_(stats) {
    for (int f = 0; f < int(f_.size()); ++f)
      for (int v : f_[f]) vf_[v].push_back(f);
  }

  // One sweep in face order (spatially coherent, cache friendly): every edge
  // shorter than `length` is tried once, edges of a moved vertex again when
  // their face comes up. Shortest-first is approximated by sweeping with a
  // slowly growing threshold (see collapse_short_edges), which avoids a global
  // heap of millions of edges.
  size_t sweep(double length) {
    const double limit2 = length * length;
    size_t before = stats_.collapses;
    for (size_t f = 0; f < f_.size(); ++f)
      for (int k = 0; k < 3 && face_alive_[f]; ++k) {
        int u = f_[f][k], v = f_[f][(k + 1) % 3];
        if (norm2(p_[u] - p_[v]) < limit2) collapse(u, v);
      }
    return stats_.collapses - before;
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
  // The one-ring of v (vertices sharing a face with it), sorted.
  void ring(int v, std::vector<int>& out) const {
    out.clear();
    for (int f : vf_[v])
      for (int w : f_[f])
        if (w != v) out.push_back(w);
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
  }

  static bool has(const std::array<int, 3>& t, int v) { return t[0] == v || t[1] == v || t[2] == v; }

  Vec3 normal(const std::array<int, 3>& t, int from, int to, Vec3 moved) const {
    auto at = [&](int v) { return v == from || v == to ? moved : p_[v]; };
    return cross(at(t[1]) - at(t[0]), at(t[2]) - at(t[0]));
  }

  void collapse(int a, int b) {
    // The two faces on edge ab and their opposite vertices.
    int shared[2], n_shared = 0;
    for (int f : vf_[a])
      if (has(f_[f], b)) {
        if (n_shared == 2) return;  // not manifold here: leave it alone
        shared[n_shared++] = f;
      }
    if (n_shared != 2) return;
    int opposite[2];
    for (int s = 0; s < 2; ++s)
      for (int v : f_[shared[s]])
        if (v != a && v != b) opposite[s] = v;
    // Link condition: the rings of a and b meet only in the two opposite
    // vertices; a valence-3 opposite vertex would be left with two faces.
    ring(a, ring_a_);
    ring(b, ring_b_);
    common_.clear();
    std::set_intersection(ring_a_.begin(), ring_a_.end(), ring_b_.begin(), ring_b_.end(),
                          std::back_inserter(common_));
    if (common_.size() != 2 || opposite[0] == opposite[1] || vf_[opposite[0]].size() <= 3 ||
        vf_[opposite[1]].size() <= 3) {
      ++stats_.refused_link;
      return;
    }
    const Vec3 mid = 0.5 * (p_[a] + p_[b]);
    for (const auto* r : {&ring_a_, &ring_b_})
      for (int w : *r)
        if (w != a && w != b && norm2(p_[w] - mid) > max2_) {
          ++stats_.refused_long;
          return;
        }
    // No face may turn by more than ~80 degrees or become degenerate.
    for (int v : {a, b})
      for (int f : vf_[v]) {
        if (f == shared[0] || f == shared[1]) continue;
        Vec3 before = normal(f_[f], -1, -1, mid), after = normal(f_[f], a, b, mid);
        double nb = norm2(before), na = norm2(after);
        if (!(na > 1e-24 * max2_ * max2_) || dot(before, after) <= 0.2 * std::sqrt(na * nb)) {
          ++stats_.refused_flip;
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
    ++stats_.collapses;
  }

  std::vector<Vec3> p_;
  std::vector<std::array<int, 3>> f_;
  std::vector<char> face_alive_, vertex_alive_;
  std::vector<std::vector<int>> vf_;  // faces around each vertex
  double max2_;
  CollapseStats& stats_;
  std::vector<int> ring_a_, ring_b_, common_;  // scratch
};

}  // namespace

TriMesh collapse_short_edges(const TriMesh& mesh, double min_edge_length, double max_edge_length,
                             CollapseStats* stats) {
  CollapseStats local;
  if (!(min_edge_length > 0) || mesh.faces.empty()) return mesh;
  Collapser collapser(mesh, std::max(min_edge_length, max_edge_length), stats ? *stats : local);
  // Thresholds growing by 1.25 from min_edge_length / 16 up to it: short
  // edges go first, as with a shortest-first heap, at a fraction of the cost
  // (a sweep that finds nothing short costs one scan of the faces). Edges
  // refused early (a neighbour in the way) often pass once their
  // neighbourhood has been coarsened, hence extra sweeps at the final length.
  for (double length = min_edge_length / 16; length < min_edge_length; length *= 1.25)
    collapser.sweep(length);
  for (int pass = 0; pass < 4; ++pass)
    if (collapser.sweep(min_edge_length) < mesh.faces.size() / 500) break;
  return collapser.result();
}

}  // namespace soupuv::proxy
