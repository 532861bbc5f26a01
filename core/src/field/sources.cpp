// Source geometry, the near/far evaluation rule, and local refinement.
#include "soupuv/field/sources.h"

#include <algorithm>
#include <cmath>

#include "soupuv/errors.h"
#include "soupuv/field/quadrature.h"
#include "soupuv/field/triangle_integrals.h"

namespace soupuv::field {

SourceGeometry make_sources(const std::vector<Vec3>& positions, const std::vector<Tri>& triangles,
                            int quadrature_degree) {
  const TriangleRule& rule = triangle_rule(quadrature_degree);
  SourceGeometry s;
  const size_t n = triangles.size();
  const int m = static_cast<int>(rule.weights.size());
  s.points_per_triangle = m;
  s.qweights = rule.weights;
  s.a.resize(n); s.b.resize(n); s.c.resize(n);
  s.centroid.resize(n); s.area.resize(n); s.radius.resize(n);
  s.qpoints.resize(n * m);
  for (size_t j = 0; j < n; ++j) {
    for (uint32_t v : triangles[j])
      if (v >= positions.size())
        throw Error(ErrorCode::invalid_input, "triangle index out of range in field sources");
    Vec3 a = positions[triangles[j][0]], b = positions[triangles[j][1]], c = positions[triangles[j][2]];
    s.a[j] = a; s.b[j] = b; s.c[j] = c;
    Vec3 g = (a + b + c) / 3.0;
    s.centroid[j] = g;
    s.area[j] = 0.5 * norm(cross(b - a, c - a));
    s.radius[j] = std::sqrt(std::max({norm2(a - g), norm2(b - g), norm2(c - g)}));
    for (int k = 0; k < m; ++k) {
      const auto& l = rule.points[k];
      s.qpoints[j * m + k] = l[0] * a + l[1] * b + l[2] * c;
    }
  }
  // Near-field threshold per degree: beyond it the rule's relative error on one
  // triangle is below ~1e-6 (measured in the tests; a higher degree converges sooner).
  s.near_factor = quadrature_degree == 2 ? 6.0 : (quadrature_degree == 4 ? 4.0 : 3.0);
  s.closed_factor = std::min(2.5, s.near_factor);
  return s;
}

namespace {
// The middle band: the degree-6 rule on triangle j, points built on the fly.
void middle_band(const SourceGeometry& s, size_t j, Vec3 x, double* phi, Vec3* E) {
  static const TriangleRule& rule = triangle_rule(6);
  const Vec3 a = s.a[j], b = s.b[j], c = s.c[j];
  double f = 0, ex = 0, ey = 0, ez = 0;
  for (size_t k = 0; k < rule.weights.size(); ++k) {
    const auto& l = rule.points[k];
    Vec3 d = x - (l[0] * a + l[1] * b + l[2] * c);
    double inv = 1.0 / std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
    double wi = rule.weights[k] * inv;
    f += wi;
    double w3 = wi * inv * inv;
    ex += w3 * d.x; ey += w3 * d.y; ez += w3 * d.z;
  }
  if (phi) *phi += f;
  if (E) *E += Vec3{ex, ey, ez};
}
}  // namespace

void near_potential_field(const SourceGeometry& s, size_t j, Vec3 x, double* phi, Vec3* E) {
  if (!(s.area[j] > 0)) return;
  if (!s.is_closed_form(j, x)) return middle_band(s, j, x, phi, E);
  TriangleIntegrals t = triangle_integrals(s.a[j], s.b[j], s.c[j], x);
  double inv = 1.0 / s.area[j];
  if (phi) *phi += t.potential * inv;
  if (E) *E += t.field * inv;
}

double unit_potential(const SourceGeometry& s, size_t j, Vec3 x) {
  if (s.is_near(j, x)) {
    double phi = 0;
    near_potential_field(s, j, x, &phi, nullptr);
    return phi;
  }
  const int m = s.points_per_triangle;
  const Vec3* q = &s.qpoints[j * m];
  double phi = 0;
  for (int k = 0; k < m; ++k) phi += s.qweights[k] / norm(x - q[k]);
  return phi;
}

void unit_potential_field(const SourceGeometry& s, size_t j, Vec3 x, double* phi, Vec3* E) {
  if (s.is_near(j, x)) return near_potential_field(s, j, x, phi, E);
  const int m = s.points_per_triangle;
  const Vec3* q = &s.qpoints[j * m];
  double f = 0;
  Vec3 e{0, 0, 0};
  for (int k = 0; k < m; ++k) {
    Vec3 d = x - q[k];
    double inv_r = 1.0 / norm(d);
    f += s.qweights[k] * inv_r;
    e += (s.qweights[k] * inv_r * inv_r * inv_r) * d;
  }
  if (phi) *phi += f;
  if (E) *E += e;
}

Refined refine_large_triangles(const Soup& soup, double ratio) {
  Refined r;
  r.positions = soup.positions;
  const size_t n = soup.triangles.size();
  if (ratio <= 0 || n == 0) {
    r.triangles = soup.triangles;
    r.parent.resize(n);
    for (size_t i = 0; i < n; ++i) r.parent[i] = static_cast<uint32_t>(i);
    return r;
  }
  std::vector<double> areas(n);
  for (size_t i = 0; i < n; ++i) areas[i] = triangle_area(soup, i);
  std::vector<double> sorted = areas;
  std::nth_element(sorted.begin(), sorted.begin() + n / 2, sorted.end());
  const double limit = ratio * sorted[n / 2];
  // Each input triangle is split on its own (new midpoint vertices are not
  // shared with neighbours: the soup has no connectivity to respect).
  std::vector<std::pair<Tri, double>> stack;
  for (size_t i = 0; i < n; ++i) {
    if (!(areas[i] > limit) || !(limit > 0)) {
      r.triangles.push_back(soup.triangles[i]);
      r.parent.push_back(static_cast<uint32_t>(i));
      continue;
    }
    ++r.split_inputs;
    stack.assign(1, {soup.triangles[i], areas[i]});
    while (!stack.empty()) {
      auto [t, area] = stack.back();
      stack.pop_back();
      if (area <= limit) {
        r.triangles.push_back(t);
        r.parent.push_back(static_cast<uint32_t>(i));
        continue;
      }
      auto mid = [&](uint32_t u, uint32_t v) {
        r.positions.push_back(0.5 * (r.positions[u] + r.positions[v]));
        return static_cast<uint32_t>(r.positions.size() - 1);
      };
      uint32_t ab = mid(t[0], t[1]), bc = mid(t[1], t[2]), ca = mid(t[2], t[0]);
      double q = area / 4;
      stack.push_back({{t[0], ab, ca}, q});
      stack.push_back({{ab, t[1], bc}, q});
      stack.push_back({{ca, bc, t[2]}, q});
      stack.push_back({{ab, bc, ca}, q});
    }
  }
  return r;
}

}  // namespace soupuv::field
