// Symmetric triangle rules without a centroid point (Strang–Fix degree 2,
// Dunavant degree 4 and 6). The constants are the published orbit
// coordinates; the tests check exactness on monomials.
#include "soupuv/field/quadrature.h"

#include "soupuv/errors.h"

namespace soupuv::field {

namespace {

// Adds the 3 points of the orbit (a, b, b) and permutations.
void orbit3(TriangleRule& r, double a, double w) {
  double b = (1.0 - a) / 2.0;
  r.points.push_back({a, b, b});
  r.points.push_back({b, a, b});
  r.points.push_back({b, b, a});
  for (int i = 0; i < 3; ++i) r.weights.push_back(w);
}

// Adds the 6 points of the orbit (a, b, c), all permutations.
void orbit6(TriangleRule& r, double a, double b, double w) {
  double c = 1.0 - a - b;
  const double p[6][3] = {{a, b, c}, {a, c, b}, {b, a, c}, {b, c, a}, {c, a, b}, {c, b, a}};
  for (auto& q : p) {
    r.points.push_back({q[0], q[1], q[2]});
    r.weights.push_back(w);
  }
}

TriangleRule make_rule(int degree) {
  TriangleRule r;
  r.degree = degree;
  if (degree == 2) {
    orbit3(r, 2.0 / 3.0, 1.0 / 3.0);
  } else if (degree == 4) {
    orbit3(r, 0.108103018168070, 0.223381589678011);
    orbit3(r, 0.816847572980459, 0.109951743655322);
  } else if (degree == 6) {
    orbit3(r, 0.501426509658179, 0.116786275726379);
    orbit3(r, 0.873821971016996, 0.050844906370207);
    orbit6(r, 0.053145049844817, 0.310352451033784, 0.082851075618374);
  }
  // Normalise so the weights sum to exactly 1 despite the printed digits.
  double s = 0;
  for (double w : r.weights) s += w;
  for (double& w : r.weights) w /= s;
  return r;
}

}  // namespace

const TriangleRule& triangle_rule(int degree) {
  static const TriangleRule r2 = make_rule(2), r4 = make_rule(4), r6 = make_rule(6);
  switch (degree) {
    case 2: return r2;
    case 4: return r4;
    case 6: return r6;
    default:
      throw Error(ErrorCode::invalid_input,
                  "quadrature degree must be 2, 4 or 6, got " + std::to_string(degree));
  }
}

}  // namespace soupuv::field
