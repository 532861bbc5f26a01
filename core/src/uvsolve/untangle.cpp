#include "uvsolve/untangle.h"

#include <Eigen/Sparse>

#include <algorithm>
#include <cmath>

#include "uvsolve/local_island.h"

namespace soupuv::uvsolve::detail {

size_t orient_islands(const Soup& soup, UvLayout& L) {
  std::vector<double> orientation(L.island_count, 0);
  for (size_t t = 0; t < L.corner_vertex.size(); ++t) {
    const double a = signed_area2(L, t);
    orientation[L.island[t]] += triangle_area(soup, t) * (a > 0 ? 1 : a < 0 ? -1 : 0);
  }
  std::vector<uint8_t> mirror(L.uv.size(), 0);
  for (size_t t = 0; t < L.corner_vertex.size(); ++t)
    if (orientation[L.island[t]] < 0)
      for (uint32_t v : L.corner_vertex[t]) mirror[v] = 1;
  for (size_t v = 0; v < L.uv.size(); ++v)
    if (mirror[v]) L.uv[v].x = -L.uv[v].x;
  return size_t(std::count_if(orientation.begin(), orientation.end(), [](double o) { return o < 0; }));
}

bool is_folded(double uv_area, double rest_area, double collapse_ratio) {
  if (rest_area == 0) return uv_area < 0;
  return !(uv_area > collapse_ratio * rest_area);
}

bool is_folded(const Soup& soup, double uv_per_length, double collapse_ratio, const UvLayout& L, size_t t) {
  return is_folded(0.5 * signed_area2(L, t), triangle_area(soup, t) * uv_per_length * uv_per_length, collapse_ratio);
}

namespace {

// ARAP on one island (local vertex numbering); returns false if the solve failed.
bool arap(const std::vector<std::array<uint32_t, 3>>& tri,
          const std::vector<transfer::detail::RestTriangle>& rest, int iterations, std::vector<Vec2>& uv) {
  const Eigen::Index n = Eigen::Index(uv.size());
  std::vector<Eigen::Triplet<double>> trip;
  double diagonal = 0;
  for (size_t t = 0; t < tri.size(); ++t) {
    const auto& r = rest[t];
    if (!r.valid) continue;
    for (int k = 0; k < 3; ++k)
      for (int l = 0; l < 3; ++l) {
        const double w = r.area * dot(r.g[k], r.g[l]);
        trip.emplace_back(tri[t][k], tri[t][l], w);
        if (k == l) diagonal += w;
      }
  }
  // A faint pull to the start removes the free translation.
  const double lambda = 1e-6 * diagonal / double(std::max<Eigen::Index>(n, 1)) + 1e-300;
  for (Eigen::Index v = 0; v < n; ++v) trip.emplace_back(v, v, lambda);
  Eigen::SparseMatrix<double> A(n, n);
  A.setFromTriplets(trip.begin(), trip.end());
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(A);
  if (solver.info() != Eigen::Success) return false;
  const std::vector<Vec2> start = uv;
  Eigen::VectorXd bx(n), by(n);
  for (int it = 0; it < iterations; ++it) {
    for (Eigen::Index v = 0; v < n; ++v) {
      bx[v] = lambda * start[v].x;
      by[v] = lambda * start[v].y;
    }
    for (size_t t = 0; t < tri.size(); ++t) {
      const auto& r = rest[t];
      if (!r.valid) continue;
      const auto J = transfer::detail::jacobian(r, {uv[tri[t][0]], uv[tri[t][1]], uv[tri[t][2]]});
      // The rotation closest to J (finite for a flipped J too).
      const double angle = std::atan2(J.j10 - J.j01, J.j00 + J.j11);
      const double c = std::cos(angle), s = std::sin(angle);
      for (int k = 0; k < 3; ++k) {
        const Vec2 g = r.g[k];
        bx[tri[t][k]] += r.area * (c * g.x - s * g.y);
        by[tri[t][k]] += r.area * (s * g.x + c * g.y);
      }
    }
    const Eigen::VectorXd x = solver.solve(bx), y = solver.solve(by);
    if (!x.allFinite() || !y.allFinite()) return false;
    for (Eigen::Index v = 0; v < n; ++v) uv[v] = {x[v], y[v]};
  }
  return true;
}

}  // namespace

bool arap_island(const Soup& soup, double uv_per_length, const std::vector<uint32_t>& tris, int iterations,
                 UvLayout& L) {
  LocalIsland m = local_island(soup, uv_per_length, tris, L);
  if (!arap(m.triangles, m.rest, iterations, m.uv)) return false;
  write_back(m, L);
  return true;
}

UntangleFigures untangle_islands(const Soup& soup, double uv_per_length, double collapse_ratio,
                                 int iterations, int threads, UvLayout& L) {
  UntangleFigures f;
  const auto islands = island_triangles(L);
  size_t folded_islands = 0, untangled = 0, bad_before = 0, bad_after = 0;
#pragma omp parallel for schedule(dynamic, 1) num_threads(std::max(1, threads)) \
    reduction(+ : folded_islands, untangled, bad_before, bad_after)
  for (size_t i = 0; i < islands.size(); ++i) {
    const auto& tris = islands[i];
    size_t bad = 0;
    for (uint32_t t : tris) bad += is_folded(soup, uv_per_length, collapse_ratio, L, t);
    bad_before += bad;
    if (bad == 0 || tris.size() < 2) {
      bad_after += bad;
      continue;
    }
    ++folded_islands;
    LocalIsland m = local_island(soup, uv_per_length, tris, L);
    if (!arap(m.triangles, m.rest, iterations, m.uv)) {
      bad_after += bad;
      continue;
    }
    size_t bad_now = 0;
    for (size_t j = 0; j < tris.size(); ++j) {
      const auto& tri = m.triangles[j];
      const Vec2 a = m.uv[tri[0]], b = m.uv[tri[1]], c = m.uv[tri[2]];
      const double area = 0.5 * cross(b - a, c - a), r = m.rest[j].valid ? m.rest[j].area : 0;
      bad_now += r == 0 ? area < 0 : !(area > collapse_ratio * r);
    }
    if (bad_now < bad) {
      ++untangled;
      write_back(m, L);
      bad_after += bad_now;
    } else {
      bad_after += bad;
    }
  }
  f.folded_islands = folded_islands;
  f.untangled_islands = untangled;
  f.bad_before = bad_before;
  f.bad_after = bad_after;
  return f;
}

}  // namespace soupuv::uvsolve::detail
