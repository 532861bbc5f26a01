// Triangle against triangle (see soupuv/geometry/triangle_triangle.h).
#include "soupuv/geometry/triangle_triangle.h"

#include <algorithm>
#include <cmath>

#include "soupuv/geometry/plane.h"

namespace soupuv::geometry {
namespace {

using Tri3 = std::array<Vec3, 3>;

// Interval of the line parameter (along dir) where triangle t crosses plane p;
// false if it does not cross.
bool crossing_interval(const Tri3& t, const Plane& p, Vec3 dir, double& lo, double& hi) {
  double d[3] = {p.at(t[0]), p.at(t[1]), p.at(t[2])};
  lo = INFINITY;
  hi = -INFINITY;
  bool any = false;
  for (int k = 0; k < 3; ++k) {
    int k1 = (k + 1) % 3;
    if (d[k] == 0) {
      double s = dot(t[k], dir);
      lo = std::min(lo, s); hi = std::max(hi, s); any = true;
    }
    if ((d[k] < 0 && d[k1] > 0) || (d[k] > 0 && d[k1] < 0)) {
      Vec3 x = t[k] + (t[k1] - t[k]) * (d[k] / (d[k] - d[k1]));
      double s = dot(x, dir);
      lo = std::min(lo, s); hi = std::max(hi, s); any = true;
    }
  }
  return any;
}

}  // namespace

bool triangles_intersect(const Tri3& a, const Tri3& b) {
  Plane pa = plane_of(a), pb = plane_of(b);
  Vec3 dir = cross(pa.n, pb.n);
  if (norm(dir) < 1e-12) return false;  // parallel or coplanar: no transversal cut
  double alo, ahi, blo, bhi;
  if (!crossing_interval(a, pb, dir, alo, ahi) || !crossing_interval(b, pa, dir, blo, bhi))
    return false;
  return std::min(ahi, bhi) - std::max(alo, blo) > 0;
}

}  // namespace soupuv::geometry
