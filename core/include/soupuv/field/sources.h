// The charged source geometry shared by the charge solvers, the FMM and the
// tracer: per triangle its vertices, centroid, area, bounding radius and
// quadrature points; and the one rule that decides how a triangle with a unit
// charge is evaluated at a point x (d = |x - centroid|, r = radius):
//   d < closed_factor * r                  -> closed form (triangle_integrals.h)
//   closed_factor * r <= d < near_factor*r -> the degree-6 rule (12 points)
//   otherwise                              -> the triangle's own quadrature rule
// The middle band exists for speed: the closed form (six atan2, three logs)
// dominated tracing, and beyond 2.5 radii the degree-6 rule is already more
// accurate (field rel. error <= 5e-6, measured) than the degree-4 rule is at
// the near_factor boundary (1.6e-5), so the model's worst error does not grow.
// "Near" (is_near) keeps its meaning: the triangles a collocation point takes
// from the precomputed sparse list and a tracer measures its distance to.
// Everything that needs "the field of triangle j at x" goes through
// unit_potential / unit_field so the solvers, the FMM near field and the
// direct-summation references agree on the model.
#pragma once

#include <cstdint>
#include <vector>

#include "soupuv/soup.h"
#include "soupuv/vec.h"

namespace soupuv::field {

struct SourceGeometry {
  std::vector<Vec3> a, b, c;         // vertices per triangle
  std::vector<Vec3> centroid;
  std::vector<double> area;
  std::vector<double> radius;        // max distance centroid -> vertex
  int points_per_triangle = 0;       // m
  std::vector<Vec3> qpoints;         // triangle j's points at [j*m, (j+1)*m)
  std::vector<double> qweights;      // m weights, sum 1
  double near_factor = 4.0;
  double closed_factor = 2.5;        // <= near_factor

  size_t size() const { return centroid.size(); }
  bool is_near(size_t j, Vec3 x) const {
    double r = near_factor * radius[j];
    return norm2(x - centroid[j]) < r * r;
  }
  bool is_closed_form(size_t j, Vec3 x) const {
    double r = closed_factor * radius[j];
    return norm2(x - centroid[j]) < r * r;
  }
};

SourceGeometry make_sources(const std::vector<Vec3>& positions, const std::vector<Tri>& triangles,
                            int quadrature_degree);

// Potential at x of triangle j carrying unit total charge.
double unit_potential(const SourceGeometry& s, size_t j, Vec3 x);
// The same for a point x that is_near triangle j (closed form or middle band);
// adds to *phi / *E.
void near_potential_field(const SourceGeometry& s, size_t j, Vec3 x, double* phi, Vec3* E);
// Potential and field (-grad phi) at x of triangle j carrying unit total charge.
void unit_potential_field(const SourceGeometry& s, size_t j, Vec3 x, double* phi, Vec3* E);

// Local refinement (§7.5): triangles with area > ratio * median area are split
// into four by their edge midpoints until none is; parent[i] names the input
// triangle of output triangle i. ratio <= 0 copies the input.
struct Refined {
  std::vector<Vec3> positions;
  std::vector<Tri> triangles;
  std::vector<uint32_t> parent;
  size_t split_inputs = 0;           // input triangles that were split
};
Refined refine_large_triangles(const Soup& soup, double ratio);

}  // namespace soupuv::field
