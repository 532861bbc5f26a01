// The tracer's batched field evaluator (see tracer_field.h).
#include "soupuv/field/tracer_field.h"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "soupuv/field/quadrature.h"
#include "soupuv/field/sources.h"
#include "soupuv/field/triangle_integrals.h"

// The point-charge loop is where tracing spends its time. The compiler will
// not vectorise it (sqrt may set errno), so it is written with intrinsics:
// AVX2+FMA (four lanes) when the CPU has them, checked once at run time,
// else SSE2 (two lanes, part of x86-64); plain C++ elsewhere.
#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
#define SOUPUV_X86_KERNELS 1
#endif

namespace soupuv::field {

namespace {

// Adds the field of the points k in [k0, n) to e (the tails of the vector loops).
void point_charges_scalar(const double* px, const double* py, const double* pz, const double* q, int k0, int n,
                          double x, double y, double z, double* e) {
  for (int k = k0; k < n; ++k) {
    const double dx = x - px[k], dy = y - py[k], dz = z - pz[k];
    const double inv = 1.0 / std::sqrt(dx * dx + dy * dy + dz * dz);
    const double w3 = q[k] * inv * inv * inv;
    e[0] += w3 * dx;
    e[1] += w3 * dy;
    e[2] += w3 * dz;
  }
}

#ifdef SOUPUV_X86_KERNELS
__attribute__((target("avx2,fma"))) void point_charges_avx2(const double* px, const double* py, const double* pz,
                                                             const double* q, int n, double x, double y, double z,
                                                             double* e) {
  const __m256d X = _mm256_set1_pd(x), Y = _mm256_set1_pd(y), Z = _mm256_set1_pd(z), one = _mm256_set1_pd(1.0);
  __m256d ex = _mm256_setzero_pd(), ey = ex, ez = ex;
  int k = 0;
  for (; k + 4 <= n; k += 4) {
    const __m256d dx = _mm256_sub_pd(X, _mm256_loadu_pd(px + k));
    const __m256d dy = _mm256_sub_pd(Y, _mm256_loadu_pd(py + k));
    const __m256d dz = _mm256_sub_pd(Z, _mm256_loadu_pd(pz + k));
    const __m256d r2 = _mm256_fmadd_pd(dz, dz, _mm256_fmadd_pd(dy, dy, _mm256_mul_pd(dx, dx)));
    const __m256d inv = _mm256_div_pd(one, _mm256_sqrt_pd(r2));
    const __m256d w3 = _mm256_mul_pd(_mm256_mul_pd(_mm256_loadu_pd(q + k), inv), _mm256_mul_pd(inv, inv));
    ex = _mm256_fmadd_pd(w3, dx, ex);
    ey = _mm256_fmadd_pd(w3, dy, ey);
    ez = _mm256_fmadd_pd(w3, dz, ez);
  }
  alignas(32) double sx[4], sy[4], sz[4];
  _mm256_store_pd(sx, ex);
  _mm256_store_pd(sy, ey);
  _mm256_store_pd(sz, ez);
  e[0] += (sx[0] + sx[1]) + (sx[2] + sx[3]);
  e[1] += (sy[0] + sy[1]) + (sy[2] + sy[3]);
  e[2] += (sz[0] + sz[1]) + (sz[2] + sz[3]);
  point_charges_scalar(px, py, pz, q, k, n, x, y, z, e);
}

void point_charges_sse2(const double* px, const double* py, const double* pz, const double* q, int n, double x,
                        double y, double z, double* e) {
  const __m128d X = _mm_set1_pd(x), Y = _mm_set1_pd(y), Z = _mm_set1_pd(z), one = _mm_set1_pd(1.0);
  __m128d ex = _mm_setzero_pd(), ey = ex, ez = ex;
  int k = 0;
  for (; k + 2 <= n; k += 2) {
    const __m128d dx = _mm_sub_pd(X, _mm_loadu_pd(px + k));
    const __m128d dy = _mm_sub_pd(Y, _mm_loadu_pd(py + k));
    const __m128d dz = _mm_sub_pd(Z, _mm_loadu_pd(pz + k));
    const __m128d r2 = _mm_add_pd(_mm_add_pd(_mm_mul_pd(dx, dx), _mm_mul_pd(dy, dy)), _mm_mul_pd(dz, dz));
    const __m128d inv = _mm_div_pd(one, _mm_sqrt_pd(r2));
    const __m128d w3 = _mm_mul_pd(_mm_mul_pd(_mm_loadu_pd(q + k), inv), _mm_mul_pd(inv, inv));
    ex = _mm_add_pd(ex, _mm_mul_pd(w3, dx));
    ey = _mm_add_pd(ey, _mm_mul_pd(w3, dy));
    ez = _mm_add_pd(ez, _mm_mul_pd(w3, dz));
  }
  alignas(16) double sx[2], sy[2], sz[2];
  _mm_store_pd(sx, ex);
  _mm_store_pd(sy, ey);
  _mm_store_pd(sz, ez);
  e[0] += sx[0] + sx[1];
  e[1] += sy[0] + sy[1];
  e[2] += sz[0] + sz[1];
  point_charges_scalar(px, py, pz, q, k, n, x, y, z, e);
}

const bool kHasAvx2 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
#endif

// Adds to e[0..3) the field at (x, y, z) of point charges q[k] at (px, py, pz)[k], k < n.
void point_charges_field(const double* px, const double* py, const double* pz, const double* q, int n,
                         double x, double y, double z, double* e) {
#ifdef SOUPUV_X86_KERNELS
  if (kHasAvx2) return point_charges_avx2(px, py, pz, q, n, x, y, z, e);
  return point_charges_sse2(px, py, pz, q, n, x, y, z, e);
#else
  point_charges_scalar(px, py, pz, q, 0, n, x, y, z, e);
#endif
}

// Adds to e the field at x of charge q spread over triangle abc by the
// degree-6 rule (12 points), built on the fly into a vectorisable block.
void degree6_field(Vec3 a, Vec3 b, Vec3 c, double q, Vec3 x, double* e) {
  static const TriangleRule& rule = triangle_rule(6);
  constexpr int kPoints = 12;
  double px[kPoints], py[kPoints], pz[kPoints], pq[kPoints];
  for (int k = 0; k < kPoints; ++k) {
    const auto& l = rule.points[k];
    const Vec3 y = l[0] * a + l[1] * b + l[2] * c;
    px[k] = y.x; py[k] = y.y; pz[k] = y.z;
    pq[k] = q * rule.weights[k];
  }
  point_charges_field(px, py, pz, pq, kPoints, x.x, x.y, x.z, e);
}

}  // namespace

// The model (sources.h) takes the closed form within closed_factor radii of a
// triangle's centroid. Between kSplitFactor and closed_factor radii the tracer
// instead splits the triangle into its four midpoint children and applies the
// degree-6 rule to each: a child has half the radius and its centroid lies
// within r/2 of the parent's, so at d >= 1.75 r every child is at least
// 2.5 of its own radii away, the distance at which the sources' model already
// trusts the degree-6 rule (field rel. error <= 5e-6). This halves the
// closed forms (six atan2, three logs each) that dominate the near field.
constexpr double kSplitFactor = 1.75;

void TracerField::near_triangle(size_t j, double q, Vec3 x, double* e) const {
  const SourceGeometry& src = fmm_.src_;
  if (!(src.area[j] > 0)) return;
  const double d2 = norm2(x - src.centroid[j]);
  const double r = src.radius[j];
  const Vec3 a = src.a[j], b = src.b[j], c = src.c[j];
  if (!src.is_closed_form(j, x)) return degree6_field(a, b, c, q, x, e);
  if (d2 >= kSplitFactor * kSplitFactor * r * r && kSplitFactor < src.closed_factor) {
    const Vec3 ab = 0.5 * (a + b), bc = 0.5 * (b + c), ca = 0.5 * (c + a);
    const double q4 = 0.25 * q;
    degree6_field(a, ab, ca, q4, x, e);
    degree6_field(ab, b, bc, q4, x, e);
    degree6_field(ca, bc, c, q4, x, e);
    degree6_field(bc, ca, ab, q4, x, e);
    return;
  }
  TriangleIntegrals t = triangle_integrals(a, b, c, x);
  const double s = q / src.area[j];
  e[0] += s * t.field.x;
  e[1] += s * t.field.y;
  e[2] += s * t.field.z;
}

TracerField::TracerField(const Fmm& fmm, const std::vector<double>& charges, int threads)
    : fmm_(fmm),
      m_(fmm.src_.points_per_triangle),
      threads_(threads > 0 ? threads : omp_get_max_threads()),
      ncoef_(fmm.ncoef_) {
  const SourceGeometry& src = fmm.src_;
  const size_t n = fmm.order_.size();
  px_.resize(n * m_); py_.resize(n * m_); pz_.resize(n * m_); pq_.resize(n * m_);
  tri_charge_.resize(n);
  for (size_t k = 0; k < n; ++k) {
    const double q = charges[fmm.order_[k]];
    tri_charge_[k] = q;
    for (int i = 0; i < m_; ++i) {
      const size_t t = k * m_ + i;
      px_[t] = fmm.points_[t].x;
      py_[t] = fmm.points_[t].y;
      pz_[t] = fmm.points_[t].z;
      pq_[t] = q * src.qweights[i];
    }
  }
  span_of_cell_.assign(fmm.scells_.size(), -1);
  for (size_t ci = 0; ci < fmm.scells_.size(); ++ci) {
    const auto& cell = fmm.scells_[ci];
    if (cell.children != 0) continue;
    Span s;
    s.mc = cell.mc;
    s.first = cell.first;
    s.count = cell.count;
    double guard = 0;
    for (int k = cell.first; k < cell.first + cell.count; ++k) {
      const uint32_t j = fmm.order_[k];
      guard = std::max(guard, norm(src.centroid[j] - cell.mc) + src.near_factor * src.radius[j]);
    }
    // A little slack so rounding in the two distance computations cannot
    // skip a triangle is_near would claim.
    guard = guard * (1 + 1e-9) + 1e-300;
    s.guard2 = guard * guard;
    span_of_cell_[ci] = static_cast<int>(spans_.size());
    spans_.push_back(s);
  }
  upward_pass();
  slot_.assign(fmm.tcells_.size(), -1);
}

// P2M at the source leaves, M2M up the tree, level by level (deepest first).
void TracerField::upward_pass() {
  const auto& cells = fmm_.scells_;
  std::vector<std::vector<int>> levels;
  for (size_t ci = 0; ci < cells.size(); ++ci) {
    if (static_cast<int>(levels.size()) <= cells[ci].level) levels.resize(cells[ci].level + 1);
    levels[cells[ci].level].push_back(static_cast<int>(ci));
  }
  M_.assign(cells.size() * ncoef_, 0.0);
  for (int level = static_cast<int>(levels.size()) - 1; level >= 0; --level) {
    const auto& ids = levels[level];
#pragma omp parallel for num_threads(threads_) schedule(dynamic, 8)
    for (long i = 0; i < static_cast<long>(ids.size()); ++i) {
      const auto& c = cells[ids[i]];
      double* M = &M_[static_cast<size_t>(ids[i]) * ncoef_];
      if (c.children == 0) {
        const size_t p0 = static_cast<size_t>(c.first) * m_;
        fmm_.basis_.p2m(c.mc, &fmm_.points_[p0], &pq_[p0], c.count * m_, M);
      } else {
        for (int k = 0; k < c.children; ++k) {
          const int ch = c.child_first + k;
          fmm_.basis_.m2m(&M_[static_cast<size_t>(ch) * ncoef_], cells[ch].mc - c.mc, M);
        }
      }
    }
  }
}

void TracerField::prepare(const std::vector<int>& leaves) {
  // Missing cells: each leaf and its ancestors up to the first computed one.
  // Slot -2 marks a cell already collected.
  std::vector<int> todo;
  for (int leaf : leaves) {
    for (int c = leaf; c >= 0 && slot_[c] == -1; c = fmm_.tcells_[c].parent) {
      slot_[c] = -2;
      todo.push_back(c);
    }
  }
  if (todo.empty()) return;
  // Parents before children: by level, then one parallel pass per level.
  std::sort(todo.begin(), todo.end(),
            [&](int a, int b) { return fmm_.tcells_[a].level < fmm_.tcells_[b].level; });
  size_t next = L_.size() / ncoef_;
  for (int c : todo) slot_[c] = static_cast<int>(next++);
  L_.resize(next * ncoef_, 0.0);
  size_t ops = 0;
  for (size_t s = 0; s < todo.size();) {
    size_t e = s;
    const int level = fmm_.tcells_[todo[s]].level;
    while (e < todo.size() && fmm_.tcells_[todo[e]].level == level) ++e;
#pragma omp parallel for num_threads(threads_) schedule(dynamic, 4) reduction(+ : ops)
    for (long i = static_cast<long>(s); i < static_cast<long>(e); ++i) {
      const int c = todo[i];
      const auto& cell = fmm_.tcells_[c];
      double* L = &L_[static_cast<size_t>(slot_[c]) * ncoef_];
      if (cell.parent >= 0)
        fmm_.basis_.l2l(&L_[static_cast<size_t>(slot_[cell.parent]) * ncoef_],
                        cell.center - fmm_.tcells_[cell.parent].center, L);
      for (int B : fmm_.m2l_[c])
        fmm_.basis_.m2l(&M_[static_cast<size_t>(B) * ncoef_], cell.center - fmm_.scells_[B].mc, L);
      ops += fmm_.m2l_[c].size();
    }
    s = e;
  }
  expansions_ += todo.size();
  m2l_ops_ += ops;
}

void TracerField::field_outside(Vec3 x, Vec3* E, double* nearest) const {
  const SourceGeometry& src = fmm_.src_;
  const auto& root = fmm_.scells_[0];
  if (nearest) *nearest = std::numeric_limits<double>::infinity();
  if (root.radius < fmm_.opt_.theta * norm(x - root.mc)) {
    fmm_.basis_.m2p(&M_[0], x - root.mc, nullptr, E);
    return;
  }
  Vec3 e{0, 0, 0};
  for (size_t k = 0; k < fmm_.order_.size(); ++k) {
    const uint32_t j = fmm_.order_[k];
    Vec3 ej{0, 0, 0};
    unit_potential_field(src, j, x, nullptr, &ej);
    e += tri_charge_[k] * ej;
    if (nearest && src.area[j] > 0 && src.is_near(j, x))
      *nearest = std::min(*nearest, point_triangle_distance(src.a[j], src.b[j], src.c[j], x));
  }
  *E += e;
}

int TracerField::locate(Vec3 x, int hint) const {
  if (hint >= 0) {
    const auto& c = fmm_.tcells_[hint];
    const Vec3 d = x - c.center;
    // Same tie rule as the descent (octant: strictly greater goes up) is not
    // needed here: any leaf whose closed box holds x gives a valid expansion.
    if (c.child_first < 0 && std::fabs(d.x) <= c.half && std::fabs(d.y) <= c.half && std::fabs(d.z) <= c.half)
      return hint;
  }
  return fmm_.locate(x);
}

void TracerField::field(int leaf, const Vec3* x, int count, Vec3* E, double* nearest) const {
  constexpr double inf = std::numeric_limits<double>::infinity();
  if (leaf < 0) {
    // Outside the target tree (callers size the region so this is rare).
    for (int i = 0; i < count; ++i) field_outside(x[i], &E[i], nearest ? &nearest[i] : nullptr);
    return;
  }
  const SourceGeometry& src = fmm_.src_;
  const auto& cell = fmm_.tcells_[leaf];
  const double* L = &L_[static_cast<size_t>(slot_[leaf]) * ncoef_];
  for (int i = 0; i < count; ++i) {
    fmm_.basis_.l2p(L, x[i] - cell.center, nullptr, &E[i]);
    if (nearest) nearest[i] = inf;
  }
  const int m = m_;
  for (int B : fmm_.near_[leaf]) {
    const Span& s = spans_[span_of_cell_[B]];
    for (int i = 0; i < count; ++i) {
      const Vec3 xi = x[i];
      double e[3] = {0, 0, 0};
      if (norm2(xi - s.mc) >= s.guard2) {
        const size_t p0 = static_cast<size_t>(s.first) * m;
        point_charges_field(&px_[p0], &py_[p0], &pz_[p0], &pq_[p0], s.count * m, xi.x, xi.y, xi.z, e);
      } else {
        for (int k = s.first; k < s.first + s.count; ++k) {
          const uint32_t j = fmm_.order_[k];
          if (!src.is_near(j, xi)) {
            const size_t p0 = static_cast<size_t>(k) * m;
            point_charges_field(&px_[p0], &py_[p0], &pz_[p0], &pq_[p0], m, xi.x, xi.y, xi.z, e);
            continue;
          }
          near_triangle(j, tri_charge_[k], xi, e);
          // Every point of the triangle lies within radius of its centroid, so
          // |x - centroid| - radius bounds the distance from below: most
          // near triangles cannot beat the nearest so far.
          if (nearest && src.area[j] > 0 && std::sqrt(norm2(xi - src.centroid[j])) - src.radius[j] < nearest[i])
            nearest[i] = std::min(nearest[i], point_triangle_distance(src.a[j], src.b[j], src.c[j], xi));
        }
      }
      E[i] += Vec3{e[0], e[1], e[2]};
    }
  }
}

size_t TracerField::memory_bytes() const {
  return (px_.size() + py_.size() + pz_.size() + pq_.size() + tri_charge_.size() + M_.size() + L_.size()) *
             sizeof(double) +
         (span_of_cell_.size() + slot_.size()) * sizeof(int) + spans_.size() * sizeof(Span);
}

}  // namespace soupuv::field
