#include "atlas/parameterize.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>

#include "atlas/stretch_descent.h"
#include "soupuv/geometry/flatten_triangle.h"
#include "soupuv/geometry/triangle_stretch.h"

namespace soupuv::atlas {
namespace {

using SpMat = Eigen::SparseMatrix<double>;
using Triplet = Eigen::Triplet<double>;

std::array<Vec3, 3> corners3d(const ChartMesh& c, int i) {
  return {c.position[c.tri[i][0]], c.position[c.tri[i][1]], c.position[c.tri[i][2]]};
}

std::array<Vec2, 3> corners_uv(const ChartMesh& c, const std::vector<Vec2>& uv, int i) {
  return {uv[c.tri[i][0]], uv[c.tri[i][1]], uv[c.tri[i][2]]};
}

// A face this small relative to the chart carries no shape; its weights would
// only blow up the solvers.
double degenerate_area(const ChartMesh& c) {
  Box3 box;
  for (const Vec3& p : c.position) box.add(p);
  double d = box.diagonal();
  return 1e-14 * d * d;
}

// Cotangent of the angle at each corner of a flattened triangle, clamped so a
// needle triangle cannot dominate the system.
std::array<double, 3> corner_cotangents(const std::array<Vec2, 3>& x) {
  std::array<double, 3> cot{};
  for (int k = 0; k < 3; ++k) {
    Vec2 a = x[(k + 1) % 3] - x[k], b = x[(k + 2) % 3] - x[k];
    double s = std::fabs(cross(a, b));
    cot[k] = s > 0 ? std::clamp(dot(a, b) / s, -1e4, 1e4) : 0.0;
  }
  return cot;
}

// The two boundary vertices farthest apart (two sweeps), pinned by LSCM.
std::pair<int, int> far_boundary_pair(const ChartMesh& c) {
  const std::vector<int>& b = c.boundary;
  auto farthest_from = [&](int v) {
    int best = b[0];
    double d = -1;
    for (int w : b)
      if (double dw = norm2(c.position[w] - c.position[v]); dw > d) { d = dw; best = w; }
    return best;
  };
  int p = farthest_from(b[0]);
  int q = farthest_from(p);
  if (q == p) q = b[(std::find(b.begin(), b.end(), p) - b.begin() + 1) % b.size()];
  return {p, q};
}

double signed_area(const std::array<Vec2, 3>& p) { return 0.5 * cross(p[1] - p[0], p[2] - p[0]); }

void scale_to_3d_area(const ChartMesh& c, std::vector<Vec2>& uv) {
  double a3 = 0, a2 = 0;
  for (size_t i = 0; i < c.tri.size(); ++i) {
    auto q = corners3d(c, static_cast<int>(i));
    a3 += 0.5 * norm(cross(q[1] - q[0], q[2] - q[0]));
    a2 += signed_area(corners_uv(c, uv, static_cast<int>(i)));
  }
  if (a2 <= 0 || a3 <= 0) return;
  double s = std::sqrt(a3 / a2);
  for (Vec2& p : uv) p = p * s;
}

bool segments_touch(Vec2 a, Vec2 b, Vec2 c, Vec2 d) {
  auto orient = [](Vec2 p, Vec2 q, Vec2 r) {
    double v = cross(q - p, r - p);
    return (v > 0) - (v < 0);
  };
  int o1 = orient(a, b, c), o2 = orient(a, b, d), o3 = orient(c, d, a), o4 = orient(c, d, b);
  if (o1 == 0 && o2 == 0) {  // collinear: overlap of the projections
    auto in = [](double lo, double hi, double x) { return std::min(lo, hi) <= x && x <= std::max(lo, hi); };
    bool use_x = std::fabs(b.x - a.x) >= std::fabs(b.y - a.y);
    auto k = [&](Vec2 p) { return use_x ? p.x : p.y; };
    return in(k(a), k(b), k(c)) || in(k(a), k(b), k(d)) || in(k(c), k(d), k(a));
  }
  return o1 * o2 <= 0 && o3 * o4 <= 0;
}

}  // namespace

std::vector<Vec2> lscm(const ChartMesh& c) {
  const int nv = static_cast<int>(c.position.size());
  auto [p0, p1] = far_boundary_pair(c);
  std::vector<Vec2> uv(nv);
  uv[p0] = {0, 0};
  uv[p1] = {norm(c.position[p1] - c.position[p0]), 0};

  // Unknowns u_i at 2i, v_i at 2i+1; the four pinned ones leave the system.
  std::vector<int> column(2 * nv, -1);
  int free_count = 0;
  for (int v = 0; v < nv; ++v)
    if (v != p0 && v != p1) { column[2 * v] = free_count++; column[2 * v + 1] = free_count++; }
  auto pinned_value = [&](int var) { return var % 2 == 0 ? uv[var / 2].x : uv[var / 2].y; };

  std::vector<Triplet> entries;
  entries.reserve(c.tri.size() * 72);
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(free_count);
  const double tiny = degenerate_area(c);
  for (size_t i = 0; i < c.tri.size(); ++i) {
    auto x = geometry::flatten_triangle(corners3d(c, static_cast<int>(i)));
    double two_area = cross(x[1] - x[0], x[2] - x[0]);
    if (two_area <= 2 * tiny) continue;
    double w = 1.0 / std::sqrt(two_area);
    // Cauchy-Riemann residual sum_k W_k U_k with W_k the edge opposite corner
    // k as a complex number: zero exactly for a similarity.
    int var[6];
    double re[6], im[6];
    for (int k = 0; k < 3; ++k) {
      Vec2 wk = x[(k + 2) % 3] - x[(k + 1) % 3];
      int v = c.tri[i][k];
      var[2 * k] = 2 * v;     re[2 * k] = w * wk.x;      im[2 * k] = w * wk.y;
      var[2 * k + 1] = 2 * v + 1; re[2 * k + 1] = -w * wk.y; im[2 * k + 1] = w * wk.x;
    }
    for (const double* row : {re, im})
      for (int a = 0; a < 6; ++a) {
        int ca = column[var[a]];
        if (ca < 0) continue;
        for (int b = 0; b < 6; ++b) {
          int cb = column[var[b]];
          if (cb >= 0) entries.emplace_back(ca, cb, row[a] * row[b]);
          else rhs[ca] -= row[a] * row[b] * pinned_value(var[b]);
        }
      }
  }
  SpMat m(free_count, free_count);
  m.setFromTriplets(entries.begin(), entries.end());
  Eigen::SimplicialLDLT<SpMat> solver(m);
  if (solver.info() != Eigen::Success) return {};
  Eigen::VectorXd x = solver.solve(rhs);
  if (solver.info() != Eigen::Success || !x.allFinite()) return {};
  for (int v = 0; v < nv; ++v)
    if (column[2 * v] >= 0) uv[v] = {x[column[2 * v]], x[column[2 * v + 1]]};
  return uv;
}

std::vector<Vec2> arap(const ChartMesh& c, std::vector<Vec2> uv, int iterations) {
  const int nv = static_cast<int>(c.position.size());
  const int nf = static_cast<int>(c.tri.size());
  if (iterations <= 0 || nv < 3) return uv;
  const int pinned = c.boundary.empty() ? 0 : c.boundary[0];
  std::vector<int> column(nv, -1);
  int free_count = 0;
  for (int v = 0; v < nv; ++v)
    if (v != pinned) column[v] = free_count++;

  std::vector<std::array<Vec2, 3>> flat(nf);
  std::vector<std::array<double, 3>> cot(nf);
  std::vector<Triplet> entries;
  entries.reserve(nf * 12);
  for (int i = 0; i < nf; ++i) {
    flat[i] = geometry::flatten_triangle(corners3d(c, i));
    cot[i] = corner_cotangents(flat[i]);
    for (int k = 0; k < 3; ++k) {
      int a = c.tri[i][(k + 1) % 3], b = c.tri[i][(k + 2) % 3];
      double w = cot[i][k];
      int ca = column[a], cb = column[b];
      if (ca >= 0) entries.emplace_back(ca, ca, w);
      if (cb >= 0) entries.emplace_back(cb, cb, w);
      if (ca >= 0 && cb >= 0) { entries.emplace_back(ca, cb, -w); entries.emplace_back(cb, ca, -w); }
    }
  }
  SpMat laplacian(free_count, free_count);
  laplacian.setFromTriplets(entries.begin(), entries.end());
  Eigen::SimplicialLDLT<SpMat> solver(laplacian);
  if (solver.info() != Eigen::Success) return uv;

  Eigen::MatrixXd rhs(free_count, 2);
  for (int it = 0; it < iterations; ++it) {
    rhs.setZero();
    for (int i = 0; i < nf; ++i) {
      // Local step: the rotation nearest the face's current Jacobian (the 2x2
      // polar decomposition in closed form).
      double s00 = 0, s01 = 0, s10 = 0, s11 = 0;
      for (int k = 0; k < 3; ++k) {
        int a = (k + 1) % 3, b = (k + 2) % 3;
        Vec2 du = uv[c.tri[i][a]] - uv[c.tri[i][b]];
        Vec2 dx = flat[i][a] - flat[i][b];
        s00 += cot[i][k] * du.x * dx.x; s01 += cot[i][k] * du.x * dx.y;
        s10 += cot[i][k] * du.y * dx.x; s11 += cot[i][k] * du.y * dx.y;
      }
      double ca = s00 + s11, sa = s10 - s01, r = std::hypot(ca, sa);
      if (r > 0) { ca /= r; sa /= r; } else { ca = 1; sa = 0; }
      for (int k = 0; k < 3; ++k) {
        int a = (k + 1) % 3, b = (k + 2) % 3;
        int va = c.tri[i][a], vb = c.tri[i][b];
        Vec2 dx = flat[i][a] - flat[i][b];
        Vec2 rdx{ca * dx.x - sa * dx.y, sa * dx.x + ca * dx.y};
        double w = cot[i][k];
        if (column[va] >= 0) {
          rhs(column[va], 0) += w * rdx.x; rhs(column[va], 1) += w * rdx.y;
          if (column[vb] < 0) { rhs(column[va], 0) += w * uv[vb].x; rhs(column[va], 1) += w * uv[vb].y; }
        }
        if (column[vb] >= 0) {
          rhs(column[vb], 0) -= w * rdx.x; rhs(column[vb], 1) -= w * rdx.y;
          if (column[va] < 0) { rhs(column[vb], 0) += w * uv[va].x; rhs(column[vb], 1) += w * uv[va].y; }
        }
      }
    }
    Eigen::MatrixXd x = solver.solve(rhs);
    if (solver.info() != Eigen::Success || !x.allFinite()) break;
    for (int v = 0; v < nv; ++v)
      if (column[v] >= 0) uv[v] = {x(column[v], 0), x(column[v], 1)};
  }
  return uv;
}

int count_flipped(const ChartMesh& c, const std::vector<Vec2>& uv) {
  const double tiny = degenerate_area(c);
  int flipped = 0;
  for (size_t i = 0; i < c.tri.size(); ++i) {
    auto q = corners3d(c, static_cast<int>(i));
    if (0.5 * norm(cross(q[1] - q[0], q[2] - q[0])) <= tiny) continue;
    flipped += signed_area(corners_uv(c, uv, static_cast<int>(i))) <= 0;
  }
  return flipped;
}

bool boundary_self_intersects(const ChartMesh& c, const std::vector<Vec2>& uv) {
  const std::vector<int>& b = c.boundary;
  const int m = static_cast<int>(b.size());
  if (m < 4) return false;
  double total = 0;
  for (int i = 0; i < m; ++i) total += norm(uv[b[(i + 1) % m]] - uv[b[i]]);
  const double cell = std::max(2 * total / m, 1e-300);
  // Uniform grid over segment boxes: only segments sharing a cell are tested.
  std::unordered_map<long long, std::vector<int>> grid;
  auto key = [](long long x, long long y) { return (x << 32) ^ (y & 0xffffffffLL); };
  for (int i = 0; i < m; ++i) {
    Vec2 a = uv[b[i]], e = uv[b[(i + 1) % m]];
    long long x0 = static_cast<long long>(std::floor(std::min(a.x, e.x) / cell));
    long long x1 = static_cast<long long>(std::floor(std::max(a.x, e.x) / cell));
    long long y0 = static_cast<long long>(std::floor(std::min(a.y, e.y) / cell));
    long long y1 = static_cast<long long>(std::floor(std::max(a.y, e.y) / cell));
    for (long long x = x0; x <= x1; ++x)
      for (long long y = y0; y <= y1; ++y) {
        std::vector<int>& bucket = grid[key(x, y)];
        for (int j : bucket) {
          int d = std::abs(i - j);
          if (d == 1 || d == m - 1) continue;  // neighbours share a vertex
          if (segments_touch(a, e, uv[b[j]], uv[b[(j + 1) % m]])) return true;
        }
        bucket.push_back(i);
      }
  }
  return false;
}

double chart_stretch_l2(const ChartMesh& c, const std::vector<Vec2>& uv) {
  double sum_l2 = 0, a3 = 0, a2 = 0;
  for (size_t i = 0; i < c.tri.size(); ++i) {
    geometry::TriangleStretch s = geometry::triangle_stretch(corners3d(c, static_cast<int>(i)),
                                         corners_uv(c, uv, static_cast<int>(i)));
    sum_l2 += s.l2_squared * s.area3d;
    a3 += s.area3d;
    a2 += std::max(0.0, s.area_uv);
  }
  if (a3 <= 0) return 1;
  return std::sqrt(sum_l2 / a3) * std::sqrt(a2 / a3);
}

ChartParameterization parameterize_chart(const ChartMesh& c, int arap_iterations,
                                         double max_stretch, int stretch_sweeps) {
  ChartParameterization r;
  std::vector<Vec2> conformal = lscm(c);
  if (conformal.empty()) { r.why = "solver"; return r; }
  std::vector<Vec2> isometric = arap(c, conformal, arap_iterations);
  // The descent starts from ARAP's result and never folds a face, so it is
  // tried first; ARAP's own result, then LSCM, are the fallbacks when the
  // descended boundary crosses itself (or ARAP folded a face over). Without
  // sweeps the ARAP and LSCM results are exactly what they were before.
  std::vector<Vec2> descended;
  if (stretch_sweeps > 0 && count_flipped(c, isometric) == 0) {
    descended = isometric;
    scale_to_3d_area(c, descended);
    descended = descend_l2_stretch(c, std::move(descended), stretch_sweeps);
  }
  r.why = "flip";
  for (std::vector<Vec2>* uv : {&descended, &isometric, &conformal}) {
    if (uv->empty()) continue;
    scale_to_3d_area(c, *uv);
    if (count_flipped(c, *uv) > 0) continue;
    if (boundary_self_intersects(c, *uv)) { r.why = "overlap"; continue; }
    r.uv = std::move(*uv);
    r.stretch_l2 = chart_stretch_l2(c, r.uv);
    r.ok = r.stretch_l2 <= max_stretch;
    r.why = r.ok ? "" : "stretch";
    return r;
  }
  r.uv = std::move(conformal);
  return r;
}

}  // namespace soupuv::atlas
