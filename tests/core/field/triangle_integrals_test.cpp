// Closed-form triangle integrals against adaptive high-order quadrature (the
// slow twin), including points in the triangle's plane and next to its edges,
// and the field against a finite-difference gradient of the potential.
#include <gtest/gtest.h>

#include <cmath>

#include "soupuv/field/quadrature.h"
#include "soupuv/field/triangle_integrals.h"
#include "soupuv/geometry/segment_triangle.h"

using namespace soupuv;
using namespace soupuv::field;

namespace {

struct Integral {
  double phi = 0;
  Vec3 field;
};

// Adaptive subdivision with the degree-6 rule: a triangle is accepted when the
// rule on it agrees with the sum over its four midpoint children.
Integral rule_on(Vec3 a, Vec3 b, Vec3 c, Vec3 x) {
  const TriangleRule& r = triangle_rule(6);
  double area = 0.5 * norm(cross(b - a, c - a));
  Integral out;
  for (size_t k = 0; k < r.weights.size(); ++k) {
    Vec3 y = r.points[k][0] * a + r.points[k][1] * b + r.points[k][2] * c;
    Vec3 d = x - y;
    double R = norm(d);
    out.phi += area * r.weights[k] / R;
    out.field += (area * r.weights[k] / (R * R * R)) * d;
  }
  return out;
}

// Refines only where the rule disagrees with its four children by more than
// this triangle's share (by area) of the tolerance, so the work concentrates
// at the (near-)singular spots.
Integral adaptive_part(Vec3 a, Vec3 b, Vec3 c, Vec3 x, double tol_per_area, int depth, bool with_field) {
  Integral whole = rule_on(a, b, c, x);
  Vec3 ab = 0.5 * (a + b), bc = 0.5 * (b + c), ca = 0.5 * (c + a);
  const Vec3 tri[4][3] = {{a, ab, ca}, {ab, b, bc}, {ca, bc, c}, {ab, bc, ca}};
  Integral sum;
  for (auto& t : tri) {
    Integral p = rule_on(t[0], t[1], t[2], x);
    sum.phi += p.phi;
    sum.field += p.field;
  }
  double area = 0.5 * norm(cross(b - a, c - a));
  double err = std::fabs(sum.phi - whole.phi) + (with_field ? norm(sum.field - whole.field) : 0.0);
  if (err < tol_per_area * area || depth == 0) return sum;
  Integral out;
  for (auto& t : tri) {
    Integral p = adaptive_part(t[0], t[1], t[2], x, tol_per_area, depth - 1, with_field);
    out.phi += p.phi;
    out.field += p.field;
  }
  return out;
}

// In the plane, a target inside the triangle is the apex of three
// sub-triangles (p, u, v); in polar coordinates around p the 1/R singularity
// cancels: integral over (p, u, v) of 1/R = integral over the edge uv of
// 2 area(p, u, v) / |y(t) - p| dt, a smooth 1D integral (Simpson here). Other
// targets use adaptive subdivision.
double polar_apex(Vec3 p, Vec3 u, Vec3 v) {
  const int n = 20000;
  double twice_area = norm(cross(u - p, v - p));
  double sum = 0;
  for (int i = 0; i <= n; ++i) {
    double t = double(i) / n;
    double w = (i == 0 || i == n) ? 1 : (i % 2 ? 4 : 2);
    sum += w * twice_area / norm(u + t * (v - u) - p);
  }
  return sum / (3.0 * n);
}

Integral adaptive(Vec3 a, Vec3 b, Vec3 c, Vec3 x, double tol, int depth, bool with_field = true) {
  double area = 0.5 * norm(cross(b - a, c - a));
  Vec3 n = normalized(cross(b - a, c - a));
  double h = dot(x - a, n);
  Vec3 p = x - h * n;
  auto side = [&](Vec3 u, Vec3 v) { return dot(cross(v - u, p - u), n); };
  bool inside = side(a, b) > 0 && side(b, c) > 0 && side(c, a) > 0;
  if (std::fabs(h) > 1e-12 || !inside) return adaptive_part(a, b, c, x, tol / area, depth, with_field);
  Integral out;
  out.phi = polar_apex(p, a, b) + polar_apex(p, b, c) + polar_apex(p, c, a);
  return out;
}

const Vec3 A{0.1, -0.2, 0.3}, B{1.3, 0.1, 0.2}, C{0.4, 0.9, -0.1};

}  // namespace

TEST(TriangleIntegrals, MatchesAdaptiveQuadratureOffPlane) {
  Vec3 n = normalized(cross(B - A, C - A));
  Vec3 g = (A + B + C) / 3.0;
  const Vec3 targets[] = {g + 0.5 * n, g - 0.05 * n, A + 0.01 * n, 0.5 * (A + B) + 0.02 * n + Vec3{0.001, 0, 0},
                          0.5 * (B + C) + 0.01 * n, Vec3{3, -2, 1}, g + Vec3{0.7, 0.7, 0.7}};
  for (Vec3 x : targets) {
    TriangleIntegrals t = triangle_integrals(A, B, C, x);
    Integral ref = adaptive(A, B, C, x, 1e-10, 9);
    EXPECT_NEAR(t.potential, ref.phi, 1e-8 * std::fabs(ref.phi));
    EXPECT_LT(norm(t.field - ref.field), 1e-7 * norm(ref.field));
  }
}

TEST(TriangleIntegrals, InPlaneAndNearEdges) {
  Vec3 g = (A + B + C) / 3.0;
  Vec3 n = normalized(cross(B - A, C - A));
  // In the plane: inside (the integrand is singular there), outside, on an
  // edge's extension, and just off an edge's midpoint.
  Vec3 mid = 0.5 * (B + C);
  Vec3 out_dir = normalized(mid - g);
  const Vec3 targets[] = {g, 0.8 * A + 0.1 * B + 0.1 * C, mid + 0.3 * out_dir, B + 0.5 * (B - A),
                          mid + 1e-3 * out_dir, mid - 0.05 * out_dir};
  for (Vec3 x : targets) {
    TriangleIntegrals t = triangle_integrals(A, B, C, x);
    Integral ref = adaptive(A, B, C, x, 1e-9, 14, false);
    EXPECT_TRUE(std::isfinite(t.potential));
    EXPECT_NEAR(t.potential, ref.phi, 1e-6 * std::fabs(ref.phi)) << x.x << " " << x.y << " " << x.z;
  }
  // In-plane fields away from the triangle.
  for (Vec3 x : {mid + 0.3 * out_dir, B + 0.5 * (B - A)}) {
    TriangleIntegrals t = triangle_integrals(A, B, C, x);
    Integral ref = adaptive(A, B, C, x, 1e-10, 9);
    EXPECT_LT(norm(t.field - ref.field), 1e-7 * norm(ref.field));
    EXPECT_NEAR(dot(t.field, n), 0.0, 1e-9);
  }
}

TEST(TriangleIntegrals, FieldIsMinusGradientAndJumpsAcrossTheFace) {
  Vec3 n = normalized(cross(B - A, C - A));
  Vec3 g = (A + B + C) / 3.0;
  for (Vec3 x : {g + 0.02 * n, 0.5 * (A + C) + 0.01 * n + Vec3{0.002, 0.001, 0}, Vec3{-0.5, 0.3, 0.4}}) {
    TriangleIntegrals t = triangle_integrals(A, B, C, x);
    const double h = 1e-6;
    for (int d = 0; d < 3; ++d) {
      Vec3 e{0, 0, 0};
      e[d] = h;
      double grad = (triangle_integrals(A, B, C, x + e).potential - triangle_integrals(A, B, C, x - e).potential) / (2 * h);
      EXPECT_NEAR(t.field[d], -grad, 1e-6 * norm(t.field) + 1e-7);
    }
  }
  // Gauss: the normal field jumps by 4π (× unit density) through the face.
  double above = dot(triangle_integrals(A, B, C, g + 1e-9 * n).field, n);
  double below = dot(triangle_integrals(A, B, C, g - 1e-9 * n).field, n);
  EXPECT_NEAR(above - below, 4 * M_PI, 1e-6);
}

TEST(TriangleIntegrals, SegmentCrossings) {
  EXPECT_TRUE(geometry::segment_crosses_triangle({0.2, 0.2, -1}, {0.2, 0.2, 1}, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}));
  EXPECT_FALSE(geometry::segment_crosses_triangle({0.8, 0.8, -1}, {0.8, 0.8, 1}, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}));
  EXPECT_FALSE(geometry::segment_crosses_triangle({0.2, 0.2, 0.1}, {0.2, 0.2, 1}, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}));
}
