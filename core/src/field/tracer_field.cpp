// The tracer's batched field evaluator (see tracer_field.h).
#include "soupuv/field/tracer_field.h"

#include <cmath>
#include <limits>

#include "soupuv/field/sources.h"
#include "soupuv/field/triangle_integrals.h"

// The point-charge loop is where tracing spends its time. The build targets
// generic x86-64 (SSE2, two lanes); an AVX2+FMA clone doubles the lanes on
// machines that have it, picked once at load time. no-math-errno lets sqrt
// vectorise (a negative argument cannot occur: it is a sum of squares).
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__)
#define SOUPUV_HOT_LOOP __attribute__((target_clones("arch=haswell", "default"), optimize("no-math-errno")))
#else
#define SOUPUV_HOT_LOOP
#endif

namespace soupuv::field {

namespace {

// Adds to e[0..3) the field at (x, y, z) of point charges q[k] at (px, py, pz)[k], k < n.
SOUPUV_HOT_LOOP
void point_charges_field(const double* px, const double* py, const double* pz, const double* q, int n,
                         double x, double y, double z, double* e) {
  double ex = 0, ey = 0, ez = 0;
#pragma omp simd reduction(+ : ex, ey, ez)
  for (int k = 0; k < n; ++k) {
    const double dx = x - px[k], dy = y - py[k], dz = z - pz[k];
    const double inv = 1.0 / std::sqrt(dx * dx + dy * dy + dz * dz);
    const double w3 = q[k] * inv * inv * inv;
    ex += w3 * dx;
    ey += w3 * dy;
    ez += w3 * dz;
  }
  e[0] += ex;
  e[1] += ey;
  e[2] += ez;
}

}  // namespace

TracerField::TracerField(const Fmm& fmm) : fmm_(fmm), m_(fmm.src_.points_per_triangle) {
  const size_t np = fmm.points_.size();
  px_.resize(np); py_.resize(np); pz_.resize(np); pq_.resize(np);
  for (size_t k = 0; k < np; ++k) {
    px_[k] = fmm.points_[k].x;
    py_[k] = fmm.points_[k].y;
    pz_[k] = fmm.points_[k].z;
    pq_[k] = fmm.point_charge_[k];
  }
  const SourceGeometry& src = fmm.src_;
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
    for (int i = 0; i < count; ++i) fmm_.evaluate(x[i], nullptr, &E[i], nearest ? &nearest[i] : nullptr);
    return;
  }
  const SourceGeometry& src = fmm_.src_;
  const auto& cell = fmm_.tcells_[leaf];
  const double* L = &fmm_.L_[static_cast<size_t>(leaf) * fmm_.ncoef_];
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
          Vec3 ej{0, 0, 0};
          near_potential_field(src, j, xi, nullptr, &ej);
          const double q = fmm_.tri_charge_[k];
          e[0] += q * ej.x;
          e[1] += q * ej.y;
          e[2] += q * ej.z;
          if (nearest && src.area[j] > 0)
            nearest[i] = std::min(nearest[i], point_triangle_distance(src.a[j], src.b[j], src.c[j], xi));
        }
      }
      E[i] += Vec3{e[0], e[1], e[2]};
    }
  }
}

size_t TracerField::memory_bytes() const {
  return (px_.size() + py_.size() + pz_.size() + pq_.size()) * sizeof(double) +
         span_of_cell_.size() * sizeof(int) + spans_.size() * sizeof(Span);
}

}  // namespace soupuv::field
