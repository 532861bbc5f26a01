#include "uvsolve/patch_relax.h"

#include <algorithm>
#include <unordered_map>

#include <Eigen/Sparse>

#include "transfer/slim.h"
#include "transfer/sym_dirichlet.h"

namespace soupuv::uvsolve::detail {

VertexTriangles::VertexTriangles(const UvLayout& L) : of(L.uv.size()) {
  for (uint32_t t = 0; t < L.corner_vertex.size(); ++t) add(t, L.corner_vertex[t]);
}

void VertexTriangles::add(uint32_t t, const std::array<uint32_t, 3>& corners) {
  for (uint32_t v : corners) {
    if (v >= of.size()) of.resize(v + 1);
    auto& list = of[v];
    if (std::find(list.begin(), list.end(), t) == list.end()) list.push_back(t);
  }
}

void VertexTriangles::remove(uint32_t t, const std::array<uint32_t, 3>& corners) {
  for (uint32_t v : corners) {
    auto& list = of[v];
    list.erase(std::remove(list.begin(), list.end(), t), list.end());
  }
}

namespace {
bool all_positive(const std::vector<std::array<uint32_t, 3>>& tris, const std::vector<Vec2>& uv) {
  for (const auto& t : tris)
    if (!(cross(uv[t[1]] - uv[t[0]], uv[t[2]] - uv[t[0]]) > 0)) return false;
  return true;
}

// The free vertices at the mean of their neighbours (uniform weights), the
// fixed ones held: one sparse solve.
void tutte_start(const std::vector<std::array<uint32_t, 3>>& tris, const std::vector<uint8_t>& fixed,
                 std::vector<Vec2>& uv) {
  std::vector<int> unknown(uv.size(), -1);
  int m = 0;
  for (size_t v = 0; v < uv.size(); ++v)
    if (!fixed[v]) unknown[v] = m++;
  std::vector<std::vector<uint32_t>> around(uv.size());
  for (const auto& t : tris)
    for (int k = 0; k < 3; ++k)
      for (int j = 1; j < 3; ++j) {
        auto& list = around[t[k]];
        const uint32_t w = t[(k + j) % 3];
        if (std::find(list.begin(), list.end(), w) == list.end()) list.push_back(w);
      }
  std::vector<Eigen::Triplet<double>> entries;
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(m, 2);
  for (size_t v = 0; v < uv.size(); ++v) {
    if (unknown[v] < 0) continue;
    entries.emplace_back(unknown[v], unknown[v], double(around[v].size()));
    for (uint32_t w : around[v]) {
      if (unknown[w] >= 0) entries.emplace_back(unknown[v], unknown[w], -1.0);
      else rhs(unknown[v], 0) += uv[w].x, rhs(unknown[v], 1) += uv[w].y;
    }
  }
  Eigen::SparseMatrix<double> A(m, m);
  A.setFromTriplets(entries.begin(), entries.end());
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(A);
  if (solver.info() != Eigen::Success) return;
  const Eigen::MatrixXd x = solver.solve(rhs);
  if (solver.info() != Eigen::Success || !x.allFinite()) return;
  for (size_t v = 0; v < uv.size(); ++v)
    if (unknown[v] >= 0) uv[v] = {x(unknown[v], 0), x(unknown[v], 1)};
}
}  // namespace

RelaxedPatch relax_patch(const Soup& soup, double uv_per_length, const UvLayout& L,
                         const VertexTriangles& incidence, const std::vector<uint32_t>& seeds, int rings,
                         int iterations) {
  RelaxedPatch p;
  if (seeds.empty() || incidence.of[seeds[0]].empty()) return p;
  const uint32_t island = L.island[incidence.of[seeds[0]][0]];
  // The patch: rings of triangles around the seeds, by shared vertices.
  std::unordered_map<uint32_t, uint32_t> local;  // layout vertex -> patch vertex
  std::vector<uint32_t> patch_vertices;
  auto local_of = [&](uint32_t v) {
    auto [it, added] = local.emplace(v, uint32_t(patch_vertices.size()));
    if (added) patch_vertices.push_back(v);
    return it->second;
  };
  std::vector<uint32_t> frontier = seeds;
  for (uint32_t v : seeds) local_of(v);
  for (int ring = 0; ring < rings && !frontier.empty(); ++ring) {
    std::vector<uint32_t> next;
    for (uint32_t v : frontier)
      for (uint32_t t : incidence.of[v]) {
        if (L.island[t] != island || std::find(p.triangles.begin(), p.triangles.end(), t) != p.triangles.end())
          continue;
        p.triangles.push_back(t);
        for (uint32_t w : L.corner_vertex[t])
          if (!local.count(w)) local_of(w), next.push_back(w);
      }
    frontier = std::move(next);
  }
  // Free: every triangle of the vertex is in the patch.
  std::vector<uint8_t> fixed(patch_vertices.size(), 1);
  for (size_t i = 0; i < patch_vertices.size(); ++i) {
    const auto& around = incidence.of[patch_vertices[i]];
    fixed[i] = !std::all_of(around.begin(), around.end(), [&](uint32_t t) {
      return std::find(p.triangles.begin(), p.triangles.end(), t) != p.triangles.end();
    });
  }
  if (std::all_of(fixed.begin(), fixed.end(), [](uint8_t f) { return f != 0; })) return p;
  std::vector<std::array<uint32_t, 3>> tris(p.triangles.size());
  std::vector<transfer::detail::RestTriangle> rest(p.triangles.size());
  std::vector<Vec2> uv(patch_vertices.size());
  for (size_t i = 0; i < patch_vertices.size(); ++i) uv[i] = L.uv[patch_vertices[i]];
  for (size_t k = 0; k < p.triangles.size(); ++k) {
    const uint32_t t = p.triangles[k];
    for (int c = 0; c < 3; ++c) tris[k][c] = local.at(L.corner_vertex[t][c]);
    rest[k] = transfer::detail::rest_triangle(soup.corner(t, 0), soup.corner(t, 1), soup.corner(t, 2), uv_per_length,
                                              1.0);
  }
  // SLIM needs every triangle positive. Where one is not (the notch is
  // folded shut), the free vertices start from the patch's Tutte embedding
  // instead: each at the mean of its neighbours, the fixed ones held (no
  // flip where the fixed outline is star-shaped around the free part).
  if (!all_positive(tris, uv)) {
    tutte_start(tris, fixed, uv);
    if (!all_positive(tris, uv)) return p;
  }
  transfer::detail::SlimOptions so;
  so.max_iterations = iterations;
  if (!transfer::detail::slim_relax(tris, rest, fixed, uv, so).started) return p;
  for (size_t i = 0; i < patch_vertices.size(); ++i)
    if (!fixed[i]) p.vertices.push_back(patch_vertices[i]), p.uv.push_back(uv[i]);
  p.relaxed = true;
  return p;
}

}  // namespace soupuv::uvsolve::detail
