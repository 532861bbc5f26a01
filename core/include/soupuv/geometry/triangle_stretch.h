// The Jacobian of one triangle's map from UV onto its 3D shape, and the
// stretch figures of Sander, Snyder, Gortler, Hoppe, "Texture mapping
// progressive meshes" (SIGGRAPH 2001): the one place atlas (charts) and
// quality (the maps' metrics) take them from.
//
//   uv_jacobian(p0, p1, p2, uv, j) -> false when the UV triangle has no area
//     p0..p2   the triangle's corners in 3D
//     uv       their UVs (either orientation)
//     j        dP/ds and dP/dt, the columns of the Jacobian of UV -> 3D
//   sander_stretch(p0, p1, p2, uv, s) -> false when the UV triangle has no
//                                        area or the figures are not finite
//     s        the Jacobian's singular values big >= small (Sander's Gamma
//              and gamma, before any global normalisation) and the squared
//              L2 stretch (big^2 + small^2) / 2
//   triangle_stretch(q, p)  (atlas's form: 3D area, signed UV area, squared
//                           L2 and the largest singular value; both 0 for a
//                           UV triangle of area <= 0, which the atlas counts
//                           as flipped)
#pragma once

#include <array>

#include "soupuv/vec.h"

namespace soupuv::geometry {

struct UvJacobian {
  Vec3 ds, dt;
};

bool uv_jacobian(Vec3 p0, Vec3 p1, Vec3 p2, const std::array<Vec2, 3>& uv, UvJacobian& j);

struct SanderStretch {
  double big = 0, small = 0;  // singular values of the Jacobian
  double l2_squared = 0;      // (big^2 + small^2) / 2
};

bool sander_stretch(Vec3 p0, Vec3 p1, Vec3 p2, const std::array<Vec2, 3>& uv, SanderStretch& s);

struct TriangleStretch {
  double area3d = 0, area_uv = 0;
  double l2_squared = 0;
  double gamma_max = 0;
};

TriangleStretch triangle_stretch(const std::array<Vec3, 3>& q, const std::array<Vec2, 3>& p);

}  // namespace soupuv::geometry
