#include "uvsolve/nest_rows.h"

#include <algorithm>
#include <cmath>

namespace soupuv::uvsolve::detail {
namespace {

// Where the line y = y0 crosses the capsule of radius g around segment
// [a, b] (all points closer than g to it): widens [lo, hi] by that span.
void capsule_span(Vec2 a, Vec2 b, double g, double y0, double& lo, double& hi) {
  for (const Vec2& e : {a, b}) {
    const double dy = y0 - e.y;
    if (std::fabs(dy) < g) {
      const double r = std::sqrt(g * g - dy * dy);
      lo = std::min(lo, e.x - r), hi = std::max(hi, e.x + r);
    }
  }
  const Vec2 d = b - a;
  const double len = norm(d);
  if (!(len > 0)) return;
  // The band around the segment's inside: the rectangle a, b moved by
  // +-g along the normal; the line meets it on its edges.
  const Vec2 n{-d.y / len * g, d.x / len * g};
  const Vec2 c[4] = {a + n, b + n, b - n, a - n};
  for (int k = 0; k < 4; ++k) {
    const Vec2 u = c[k], v = c[(k + 1) % 4];
    if ((u.y - y0) * (v.y - y0) > 0) continue;
    if (u.y == v.y) {
      lo = std::min({lo, u.x, v.x}), hi = std::max({hi, u.x, v.x});
    } else {
      const double x = u.x + (y0 - u.y) / (v.y - u.y) * (v.x - u.x);
      lo = std::min(lo, x), hi = std::max(hi, x);
    }
  }
}

}  // namespace

double least_clear_shift(const RowTriangle& fixed, const RowTriangle& moving, double gap) {
  double least = -INFINITY;
  for (int k = 0; k < 3; ++k) {
    const Vec2 a = fixed[k], b = fixed[(k + 1) % 3];
    // A corner of the moving triangle against an edge of the fixed one.
    for (const Vec2& p : moving) {
      double lo = INFINITY, hi = -INFINITY;
      capsule_span(a, b, gap, p.y, lo, hi);
      if (hi > lo) least = std::max(least, hi - p.x);
    }
    // A corner of the fixed triangle against an edge of the moving one:
    // a - (s, 0) within the moving edge's capsule.
    const Vec2 c = moving[k], d = moving[(k + 1) % 3];
    for (const Vec2& p : fixed) {
      double lo = INFINITY, hi = -INFINITY;
      capsule_span(c, d, gap, p.y, lo, hi);
      if (hi > lo) least = std::max(least, p.x - lo);
    }
  }
  return least;
}

double RowNester::shift_for(const RowTriangle* tris, size_t count) const {
  double shift = placed_.empty() ? 0 : placed_.back().left;
  // Latest islands first: they are the ones within reach; an island whose
  // box ends a gap before the shift found so far cannot raise it.
  for (size_t k = placed_.size(); k-- > 0;) {
    const Placed& p = placed_[k];
    if (p.right + gap_ <= shift) continue;
    for (size_t i = p.first; i < p.first + p.count; ++i)
      for (size_t j = 0; j < count; ++j) shift = std::max(shift, least_clear_shift(tris_[i], tris[j], gap_));
  }
  return shift;
}

void RowNester::add(const RowTriangle* tris, size_t count, double width, double shift) {
  placed_.push_back({tris_.size(), count, shift, shift + width});
  for (size_t j = 0; j < count; ++j) {
    RowTriangle t = tris[j];
    for (Vec2& p : t) p.x += shift;
    tris_.push_back(t);
  }
  length_ = std::max(length_, shift + width);
}

}  // namespace soupuv::uvsolve::detail
