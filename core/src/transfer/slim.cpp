#include "transfer/slim.h"

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>

#include <algorithm>
#include <cmath>
#include <limits>

namespace soupuv::transfer::detail {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr uint32_t kFixed = UINT32_MAX;

std::array<Vec2, 3> corners_of(const std::array<uint32_t, 3>& t, const std::vector<Vec2>& uv) {
  return {uv[t[0]], uv[t[1]], uv[t[2]]};
}

}  // namespace

// J = q Rot(a2) + r Ref(a1) with q e^{i a2} = e + i h and r e^{i a1} = f + i g
// (e, f, g, h below), so J = Rot(phi) diag(q + r, q - r) Rot(theta) with
// phi = (a1 + a2) / 2 and U V^T = Rot(a2). Everything the step needs comes
// from cos a2, sin a2 and the double angle 2 phi by sums and products: no
// angle is formed (the atan2s, sines and cosines took ~8 % of the SLIM
// solves' time on the 124k scan, docs/tuning.md, session 39).
LocalTarget local_target(const Jacobian& J) {
  const double e = 0.5 * (J.j00 + J.j11), f = 0.5 * (J.j00 - J.j11);
  const double g = 0.5 * (J.j10 + J.j01), h = 0.5 * (J.j10 - J.j01);
  const double q = std::sqrt(e * e + h * h), r = std::sqrt(f * f + g * g);
  const double s1 = q + r, s2 = std::max(q - r, 1e-12);  // det > 0: s2 > 0
  auto w2 = [](double s) { return (1 + s) * (1 + s * s) / (s * s * s); };
  const double w1 = w2(s1), w2v = w2(s2);
  // cos a2, sin a2 (q > r >= 0 when det > 0), then cos 2phi, sin 2phi; when
  // r = 0, 2phi = a2 (w1 = w2 then, and any U will do).
  const double ca = q > 0 ? e / q : 1, sa = q > 0 ? h / q : 0;
  const double cos2 = r > 0 ? (f * ca - g * sa) / r : ca, sin2 = r > 0 ? (g * ca + f * sa) / r : sa;
  // U diag(w1, w2) U^T with U = Rot(phi): cos^2 phi = (1 + cos 2phi) / 2, ...
  const double cc = 0.5 * (1 + cos2), ss = 0.5 * (1 - cos2), cs = 0.5 * sin2;
  LocalTarget t;
  t.m00 = w1 * cc + w2v * ss;
  t.m01 = (w1 - w2v) * cs;
  t.m11 = w1 * ss + w2v * cc;
  t.r00 = ca, t.r01 = -sa, t.r10 = sa, t.r11 = ca;
  return t;
}

namespace {

// Largest t in (0, cap] keeping det(J + t dJ) > 0 (with a margin), for a
// triangle positive at t = 0.
double safe_step(const RestTriangle& r, const std::array<Vec2, 3>& uv, const std::array<Vec2, 3>& d,
                 double cap = 1) {
  const Jacobian A = jacobian(r, uv), B = jacobian(r, d);
  const double c0 = A.det();
  const double c1 = A.j00 * B.j11 + A.j11 * B.j00 - A.j01 * B.j10 - A.j10 * B.j01;
  const double c2 = B.det();
  double root = kInf;
  auto take = [&](double t) { if (t > 0) root = std::min(root, t); };
  if (std::abs(c2) < 1e-300 * std::abs(c1) || c2 == 0) {
    if (c1 != 0) take(-c0 / c1);
  } else {
    const double disc = c1 * c1 - 4 * c2 * c0;
    if (disc >= 0) {
      const double sq = std::sqrt(disc);
      // Numerically stable roots.
      const double qv = -0.5 * (c1 + (c1 >= 0 ? sq : -sq));
      if (qv != 0) take(c0 / qv);
      take(qv / c2);
    }
  }
  return std::min(cap, 0.8 * root);
}

// Gives each free vertex its index among the unknowns (kFixed for a fixed
// one); returns how many are free.
uint32_t number_free_vertices(const std::vector<uint8_t>& fixed, std::vector<uint32_t>& unknown) {
  unknown.assign(fixed.size(), kFixed);
  uint32_t count = 0;
  for (size_t v = 0; v < fixed.size(); ++v)
    if (!fixed[v]) unknown[v] = count++;
  return count;
}

// One flip-free backtracking step: alpha starts at the largest step (<= 1)
// that keeps every triangle positive, then halves until `energy` drops.
// On success uv moves to uv + alpha step and the new energy is returned;
// otherwise uv is unchanged and +inf is returned.
template <class Energy>
double flip_free_backtrack(const std::vector<std::array<uint32_t, 3>>& triangles,
                           const std::vector<RestTriangle>& rest, std::vector<Vec2>& uv,
                           const std::vector<Vec2>& step, std::vector<Vec2>& target, double current,
                           const Energy& energy) {
  double alpha = 1;
  for (size_t t = 0; t < triangles.size(); ++t)
    if (rest[t].valid)
      alpha = std::min(alpha, safe_step(rest[t], corners_of(triangles[t], uv),
                                        corners_of(triangles[t], step), alpha));
  for (int halving = 0; halving < 30 && alpha > 1e-12; ++halving, alpha *= 0.5) {
    for (size_t v = 0; v < uv.size(); ++v) target[v] = uv[v] + step[v] * alpha;
    const double next = energy(target);
    if (next < current) {
      uv.swap(target);
      return next;
    }
  }
  return kInf;
}

// One triangle's S and U terms (see mesh_l2_form); false when not positive.
bool l2_terms(const RestTriangle& r, const std::array<Vec2, 3>& uv, double& s, double& u) {
  const Jacobian J = jacobian(r, uv);
  const double d = J.det();
  if (!(d > 0)) return false;
  s = r.area * 0.5 * J.frobenius2() / (d * d);
  u = r.area * d;
  return true;
}

// After a backtracked step to energy `next` in iteration `it`: records it
// and says whether both solvers go on (no decrease, or a relative decrease
// below min_relative_decrease, ends them).
bool keep_going(double next, int it, double min_relative_decrease, double& current, SlimResult& result) {
  if (!(next < current)) return false;
  const double gain = (current - next) / current;
  current = next;
  result.iterations = it + 1;
  return !(gain < min_relative_decrease);
}

}  // namespace

double mesh_energy(const std::vector<std::array<uint32_t, 3>>& triangles,
                   const std::vector<RestTriangle>& rest, const std::vector<Vec2>& uv) {
  double sum = 0;
  for (size_t t = 0; t < triangles.size(); ++t) {
    if (!rest[t].valid) continue;
    sum += energy(rest[t], corners_of(triangles[t], uv));
    if (!std::isfinite(sum)) return kInf;
  }
  return sum;
}

SlimResult slim_relax(const std::vector<std::array<uint32_t, 3>>& triangles,
                      const std::vector<RestTriangle>& rest, const std::vector<uint8_t>& fixed,
                      std::vector<Vec2>& uv, const SlimOptions& options) {
  SlimResult result;
  result.energy_before = result.energy_after = mesh_energy(triangles, rest, uv);
  if (!std::isfinite(result.energy_before)) return result;
  result.started = true;
  std::vector<uint32_t> unknown;
  const uint32_t free_count = number_free_vertices(fixed, unknown);
  if (free_count == 0) return result;
  const Eigen::Index n = 2 * Eigen::Index(free_count);

  using Triplet = Eigen::Triplet<double>;
  std::vector<Triplet> triplets;
  Eigen::SparseMatrix<double> H(n, n);
  Eigen::VectorXd rhs(n);
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver;
  bool analysed = false;
  std::vector<uint32_t> slot;           // triplet -> its entry in H
  std::vector<uint8_t> first_in_slot;  // the first triplet of its entry
  std::vector<Vec2> target(uv.size()), step(uv.size());

  double current = result.energy_before;
  for (int it = 0; it < options.max_iterations; ++it) {
    // Local step + global assembly: sum_t A_t ||W_t (J_t - R_t)||^2, whose
    // gradient in corner k's UV is 2 A M (J - R) g_k; the unknowns of a
    // vertex are (u, v) at 2i, 2i + 1.
    triplets.clear();
    rhs.setZero();
    for (size_t t = 0; t < triangles.size(); ++t) {
      const RestTriangle& r = rest[t];
      if (!r.valid) continue;
      const auto& tri = triangles[t];
      const LocalTarget L = local_target(jacobian(r, corners_of(tri, uv)));
      const double M[2][2] = {{L.m00, L.m01}, {L.m01, L.m11}};
      for (int k = 0; k < 3; ++k) {
        const uint32_t ik = unknown[tri[k]];
        if (ik == kFixed) continue;
        // (M R g_k): R g_k first.
        const Vec2 Rg{L.r00 * r.g[k].x + L.r01 * r.g[k].y, L.r10 * r.g[k].x + L.r11 * r.g[k].y};
        rhs[2 * ik] += r.area * (M[0][0] * Rg.x + M[0][1] * Rg.y);
        rhs[2 * ik + 1] += r.area * (M[1][0] * Rg.x + M[1][1] * Rg.y);
        for (int l = 0; l < 3; ++l) {
          const double gg = r.area * dot(r.g[k], r.g[l]);
          const uint32_t il = unknown[tri[l]];
          for (int i = 0; i < 2; ++i)
            for (int j = 0; j < 2; ++j) {
              const double value = M[i][j] * gg;
              if (il == kFixed) {
                const double xl = j == 0 ? uv[tri[l]].x : uv[tri[l]].y;
                rhs[2 * ik + i] -= value * xl;
              } else {
                triplets.emplace_back(2 * ik + i, 2 * il + j, value);
              }
            }
        }
      }
    }
    // A faint pull toward the current UVs: an island with no fixed vertex is
    // free to translate, which would leave the system singular.
    double diagonal = 0;
    for (const Triplet& e : triplets)
      if (e.row() == e.col()) diagonal += e.value();
    const double lambda = 1e-7 * diagonal / double(n) + 1e-300;
    for (size_t v = 0; v < uv.size(); ++v) {
      const uint32_t i = unknown[v];
      if (i == kFixed) continue;
      triplets.emplace_back(2 * i, 2 * i, lambda);
      triplets.emplace_back(2 * i + 1, 2 * i + 1, lambda);
      rhs[2 * i] += lambda * uv[v].x;
      rhs[2 * i + 1] += lambda * uv[v].y;
    }
    // The triplets come in the same order with the same positions every
    // iteration (only their values change): the first assembly records each
    // one's slot in H, and later ones write the values straight there, as
    // setFromTriplets would (a duplicate's first value, then the others
    // added in order), without its sort and copies.
    if (!analysed) {
      H.setFromTriplets(triplets.begin(), triplets.end());
      slot.resize(triplets.size());
      first_in_slot.assign(triplets.size(), 0);
      std::vector<uint8_t> seen(size_t(H.nonZeros()), 0);
      for (size_t k = 0; k < triplets.size(); ++k) {
        const auto* inner = H.innerIndexPtr();
        const auto b = H.outerIndexPtr()[triplets[k].col()], e = H.outerIndexPtr()[triplets[k].col() + 1];
        slot[k] = uint32_t(std::lower_bound(inner + b, inner + e, triplets[k].row()) - inner);
        if (!seen[slot[k]]) seen[slot[k]] = first_in_slot[k] = 1;
      }
      solver.analyzePattern(H);
      analysed = true;
    } else {
      double* value = H.valuePtr();
      for (size_t k = 0; k < triplets.size(); ++k)
        value[slot[k]] = first_in_slot[k] ? triplets[k].value() : value[slot[k]] + triplets[k].value();
    }
    solver.factorize(H);
    if (solver.info() != Eigen::Success) break;
    const Eigen::VectorXd x = solver.solve(rhs);
    if (solver.info() != Eigen::Success || !x.allFinite()) break;

    // Flip-free step bound, then backtracking on the true energy.
    for (size_t v = 0; v < uv.size(); ++v) {
      const uint32_t i = unknown[v];
      step[v] = i == kFixed ? Vec2{0, 0} : Vec2{x[2 * i] - uv[v].x, x[2 * i + 1] - uv[v].y};
    }
    const double next = flip_free_backtrack(
        triangles, rest, uv, step, target, current,
        [&](const std::vector<Vec2>& x) { return mesh_energy(triangles, rest, x); });
    if (!keep_going(next, it, options.min_relative_decrease, current, result)) break;
    if (options.stop_after && options.stop_after(it + 1, uv)) break;
  }
  result.energy_after = current;
  return result;
}

double mesh_l2_form(const std::vector<std::array<uint32_t, 3>>& triangles,
                    const std::vector<RestTriangle>& rest, const std::vector<Vec2>& uv,
                    double others_s, double others_u) {
  double S = others_s, U = others_u;
  for (size_t t = 0; t < triangles.size(); ++t) {
    if (!rest[t].valid) continue;
    double s, u;
    if (!l2_terms(rest[t], corners_of(triangles[t], uv), s, u)) return kInf;
    S += s;
    U += u;
  }
  return S * U;
}

SlimResult l2_relax(const std::vector<std::array<uint32_t, 3>>& triangles,
                    const std::vector<RestTriangle>& rest, const std::vector<uint8_t>& fixed,
                    std::vector<Vec2>& uv, double others_s, double others_u,
                    const SlimOptions& options) {
  SlimResult result;
  result.energy_before = result.energy_after = mesh_l2_form(triangles, rest, uv, others_s, others_u);
  if (!std::isfinite(result.energy_before)) return result;
  result.started = true;
  std::vector<uint32_t> unknown;
  const uint32_t free_count = number_free_vertices(fixed, unknown);
  if (free_count == 0) return result;
  const Eigen::Index n = 2 * Eigen::Index(free_count);

  // Preconditioner: the Dirichlet matrix of the rest shapes, scaled so that
  // a unit step is about a Newton step of F near an isometry (d2 S ~ 3 x the
  // Dirichlet form per unit of area, times U).
  double U = others_u, S = others_s;
  for (size_t t = 0; t < triangles.size(); ++t) {
    double s, u;
    if (rest[t].valid && l2_terms(rest[t], corners_of(triangles[t], uv), s, u)) S += s, U += u;
  }
  std::vector<Eigen::Triplet<double>> triplets;
  for (size_t t = 0; t < triangles.size(); ++t) {
    const RestTriangle& r = rest[t];
    if (!r.valid) continue;
    for (int k = 0; k < 3; ++k) {
      const uint32_t ik = unknown[triangles[t][k]];
      if (ik == kFixed) continue;
      for (int l = 0; l < 3; ++l) {
        const uint32_t il = unknown[triangles[t][l]];
        if (il == kFixed) continue;
        const double value = 3 * U * r.area * dot(r.g[k], r.g[l]);
        triplets.emplace_back(2 * ik, 2 * il, value);
        triplets.emplace_back(2 * ik + 1, 2 * il + 1, value);
      }
    }
  }
  double diagonal = 0;
  for (const auto& e : triplets)
    if (e.row() == e.col()) diagonal += e.value();
  for (Eigen::Index i = 0; i < n; ++i) triplets.emplace_back(i, i, 1e-7 * diagonal / double(n) + 1e-300);
  Eigen::SparseMatrix<double> P(n, n);
  P.setFromTriplets(triplets.begin(), triplets.end());
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(P);
  if (solver.info() != Eigen::Success) return result;

  Eigen::VectorXd grad(n), previous_x, previous_grad;
  bool has_previous = false;
  constexpr size_t kMemory = 8;
  std::vector<Eigen::VectorXd> pairs_s, pairs_y;
  auto flat = [&](const std::vector<Vec2>& p) {
    Eigen::VectorXd out(n);
    for (size_t v = 0; v < p.size(); ++v)
      if (unknown[v] != kFixed) out[2 * unknown[v]] = p[v].x, out[2 * unknown[v] + 1] = p[v].y;
    return out;
  };
  std::vector<Vec2> step(uv.size()), target(uv.size());
  double current = result.energy_before;
  for (int it = 0; it < options.max_iterations; ++it) {
    // S, U and dF = U dS + S dU.
    S = others_s, U = others_u;
    for (size_t t = 0; t < triangles.size(); ++t) {
      double s, u;
      if (rest[t].valid && l2_terms(rest[t], corners_of(triangles[t], uv), s, u)) S += s, U += u;
    }
    grad.setZero();
    for (size_t t = 0; t < triangles.size(); ++t) {
      const RestTriangle& r = rest[t];
      if (!r.valid) continue;
      const Jacobian J = jacobian(r, corners_of(triangles[t], uv));
      const double d = J.det(), f = J.frobenius2();
      for (int k = 0; k < 3; ++k) {
        const uint32_t ik = unknown[triangles[t][k]];
        if (ik == kFixed) continue;
        const Vec2 g = r.g[k];
        const Vec2 Jg{J.j00 * g.x + J.j01 * g.y, J.j10 * g.x + J.j11 * g.y};
        const Vec2 Cg{J.j11 * g.x - J.j10 * g.y, -J.j01 * g.x + J.j00 * g.y};
        const Vec2 ds = (Jg * (1 / (d * d)) - Cg * (f / (d * d * d))) * r.area;
        const Vec2 du = Cg * r.area;
        grad[2 * ik] += U * ds.x + S * du.x;
        grad[2 * ik + 1] += U * ds.y + S * du.y;
      }
    }
    // L-BFGS direction (two-loop recursion) with the Dirichlet matrix as
    // the initial inverse Hessian; the plain preconditioned gradient when
    // the pairs do not give a descent direction.
    if (has_previous) {
      const Eigen::VectorXd sk = flat(uv) - previous_x, yk = grad - previous_grad;
      if (sk.dot(yk) > 1e-12 * sk.norm() * yk.norm()) {
        pairs_s.push_back(sk);
        pairs_y.push_back(yk);
        if (pairs_s.size() > kMemory) pairs_s.erase(pairs_s.begin()), pairs_y.erase(pairs_y.begin());
      }
    }
    Eigen::VectorXd q = grad;
    std::vector<double> a(pairs_s.size());
    for (size_t i = pairs_s.size(); i-- > 0;) {
      a[i] = pairs_s[i].dot(q) / pairs_y[i].dot(pairs_s[i]);
      q -= a[i] * pairs_y[i];
    }
    Eigen::VectorXd x = solver.solve(q);
    for (size_t i = 0; i < pairs_s.size(); ++i) {
      const double b = pairs_y[i].dot(x) / pairs_y[i].dot(pairs_s[i]);
      x += (a[i] - b) * pairs_s[i];
    }
    if (!x.allFinite() || !(x.dot(grad) > 0)) {
      pairs_s.clear();
      pairs_y.clear();
      x = solver.solve(grad);
      if (!x.allFinite()) break;
    }
    previous_x = flat(uv);
    previous_grad = grad;
    has_previous = true;
    for (size_t v = 0; v < uv.size(); ++v) {
      const uint32_t i = unknown[v];
      step[v] = i == kFixed ? Vec2{0, 0} : Vec2{-x[2 * i], -x[2 * i + 1]};
    }
    const double next = flip_free_backtrack(
        triangles, rest, uv, step, target, current, [&](const std::vector<Vec2>& x) {
          return mesh_l2_form(triangles, rest, x, others_s, others_u);
        });
    if (!keep_going(next, it, options.min_relative_decrease, current, result)) break;
  }
  result.energy_after = current;
  return result;
}

}  // namespace soupuv::transfer::detail
