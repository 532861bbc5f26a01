// Symmetric quadrature rules on a triangle (paper §7.4). None has a point at
// the centroid, because the centroid is where the potential is collocated.
//
//   const TriangleRule& rule = triangle_rule(4);  // degree 2, 4 or 6
//   sum_k rule.weights[k] * f(a*l0 + b*l1 + c*l2) ~ (1/area) * integral of f
//
// Weights sum to 1 (multiply by the area for an integral); the points are
// barycentric coordinates (l0, l1, l2).
#pragma once

#include <array>
#include <vector>

namespace soupuv::field {

struct TriangleRule {
  int degree = 0;                               // exact for polynomials up to this degree
  std::vector<std::array<double, 3>> points;    // barycentric
  std::vector<double> weights;                  // sum to 1
};

// Degree 2 (3 points), 4 (6 points) or 6 (12 points); throws Error{invalid_input} otherwise.
const TriangleRule& triangle_rule(int degree);

}  // namespace soupuv::field
