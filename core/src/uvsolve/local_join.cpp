#include "uvsolve/local_join.h"

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>

#include <array>
#include <cmath>
#include <limits>

#include "transfer/slim.h"

namespace soupuv::uvsolve::detail {

namespace {

constexpr uint32_t kNone = std::numeric_limits<uint32_t>::max();

// LSCM's conformal energy over `tris` (local triangles with their rest
// shapes), the vertices with pinned[v] held at uv[v]: sets the others in
// uv. The energy of triangle t is area * ((J00 - J11)^2 + (J01 + J10)^2)
// with J = sum_k uv_k g_k^T, zero exactly for a similarity that keeps the
// rest triangle's (the soup's) orientation. False when the system is
// singular.
bool pinned_conformal_map(const std::vector<std::array<uint32_t, 3>>& tris,
                          const std::vector<transfer::detail::RestTriangle>& rest,
                          const std::vector<uint8_t>& pinned, std::vector<Vec2>& uv) {
  std::vector<uint32_t> unknown(uv.size(), kNone);
  uint32_t n = 0;
  for (const auto& t : tris)
    for (uint32_t v : t)
      if (!pinned[v] && unknown[v] == kNone) unknown[v] = n++;
  if (n == 0) return true;
  std::vector<Eigen::Triplet<double>> entries;
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(2 * n);
  for (size_t k = 0; k < tris.size(); ++k) {
    const transfer::detail::RestTriangle& r = rest[k];
    if (!r.valid) continue;
    // Two residuals, a = J00 - J11 and b = J01 + J10: coefficients on the
    // unknowns (u at 2i, v at 2i + 1) and the pinned vertices' constant part.
    std::array<std::pair<uint32_t, double>, 6> a, b;
    int count = 0;
    double a0 = 0, b0 = 0;
    for (int c = 0; c < 3; ++c) {
      const uint32_t v = tris[k][c];
      const Vec2 g = r.g[c];
      if (unknown[v] == kNone) {
        a0 += uv[v].x * g.x - uv[v].y * g.y;
        b0 += uv[v].x * g.y + uv[v].y * g.x;
        continue;
      }
      const uint32_t i = unknown[v];
      a[count] = {2 * i, g.x}, b[count++] = {2 * i, g.y};
      a[count] = {2 * i + 1, -g.y}, b[count++] = {2 * i + 1, g.x};
    }
    for (int p = 0; p < count; ++p) {
      rhs[a[p].first] -= r.area * a[p].second * a0;
      rhs[b[p].first] -= r.area * b[p].second * b0;
      for (int q = 0; q < count; ++q) {
        entries.emplace_back(a[p].first, a[q].first, r.area * a[p].second * a[q].second);
        entries.emplace_back(b[p].first, b[q].first, r.area * b[p].second * b[q].second);
      }
    }
  }
  Eigen::SparseMatrix<double> N(2 * n, 2 * n);
  N.setFromTriplets(entries.begin(), entries.end());
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(N);
  if (solver.info() != Eigen::Success) return false;
  const Eigen::VectorXd x = solver.solve(rhs);
  if (solver.info() != Eigen::Success || !x.allFinite()) return false;
  for (size_t v = 0; v < uv.size(); ++v)
    if (unknown[v] != kNone) uv[v] = {x[2 * unknown[v]], x[2 * unknown[v] + 1]};
  return true;
}

// One try: the larger island's triangles from `movable` on (and the smaller
// island's) are mapped anew; the vertices of the others stay where they are.
Outcome join_with(const PieceMesh& m, const std::vector<uint32_t>& tris, size_t larger,
                  const std::vector<uint8_t>& movable, const std::vector<Vec2>& current, double cell,
                  double max_stretch, int solve_iterations, Piece& out) {
  const size_t nv = current.size();
  std::vector<uint8_t> pinned(nv, 0);
  std::vector<std::array<uint32_t, 3>> part;
  std::vector<transfer::detail::RestTriangle> part_rest;
  for (size_t k = 0; k < m.triangles.size(); ++k) {
    if (k < larger && !movable[k]) {
      for (uint32_t v : m.triangles[k]) pinned[v] = 1;
      continue;
    }
    part.push_back(m.triangles[k]);
    part_rest.push_back(m.rest[k]);
  }
  // At least two pinned vertices hold the part's map in place.
  std::vector<uint8_t> counted(nv, 0);
  int held = 0;
  for (const auto& t : part)
    for (uint32_t v : t)
      if (pinned[v] && !counted[v]) counted[v] = 1, ++held;
  if (held < 2) return Outcome::parts;
  std::vector<Vec2> uv = current;
  if (!pinned_conformal_map(part, part_rest, pinned, uv)) return Outcome::flip;
  for (const auto& t : part)
    if (!(cross(uv[t[1]] - uv[t[0]], uv[t[2]] - uv[t[0]]) > 0)) return Outcome::flip;
  transfer::detail::SlimOptions so;
  so.max_iterations = solve_iterations;
  if (!transfer::detail::slim_relax(part, part_rest, pinned, uv, so).started) return Outcome::flip;
  return judge_piece(m, tris, std::move(uv), cell, max_stretch, out);
}

}  // namespace

Outcome join_locally(const PieceMesh& m, const std::vector<uint32_t>& tris, size_t larger, const UvLayout& L,
                     double cell, double max_stretch, int solve_iterations, Piece& out) {
  const size_t nv = m.chart.position.size();
  // The larger island's vertices at their UVs.
  std::vector<Vec2> uv(nv, Vec2{0, 0});
  std::vector<uint8_t> known(nv, 0);
  for (size_t k = 0; k < larger; ++k)
    for (int c = 0; c < 3; ++c) {
      const uint32_t v = m.triangles[k][c];
      const Vec2 p = L.uv[L.corner_vertex[tris[k]][c]];
      if (known[v] && !(uv[v].x == p.x && uv[v].y == p.y)) return Outcome::parts;
      uv[v] = p;
      known[v] = 1;
    }
  // The join's map keeps the soup's orientation, as flatten()'s does: a
  // larger island laid out mirrored is mirrored back first (its shape is
  // the same), else every triangle of the smaller one would fold.
  double signed_area2 = 0;
  for (size_t k = 0; k < larger; ++k) {
    const auto& t = m.triangles[k];
    signed_area2 += cross(uv[t[1]] - uv[t[0]], uv[t[2]] - uv[t[0]]);
  }
  if (signed_area2 < 0)
    for (Vec2& p : uv) p.x = -p.x;
  // First the larger island as it is; where the smaller one's map would
  // fold against it, once more with the larger island's triangles at the
  // seam (those with a vertex the smaller island shares) free to give way.
  std::vector<uint8_t> movable(larger, 0);
  const Outcome first = join_with(m, tris, larger, movable, uv, cell, max_stretch, solve_iterations, out);
  if (first != Outcome::flip) return first;
  std::vector<uint8_t> at_seam(nv, 0);
  for (size_t k = larger; k < m.triangles.size(); ++k)
    for (uint32_t v : m.triangles[k])
      if (known[v]) at_seam[v] = 1;
  for (size_t k = 0; k < larger; ++k)
    for (uint32_t v : m.triangles[k])
      if (at_seam[v]) movable[k] = 1;
  return join_with(m, tris, larger, movable, uv, cell, max_stretch, solve_iterations, out);
}

}  // namespace soupuv::uvsolve::detail
