// Distortion of one triangle's map between its 3D shape and its UV image,
// after Sander, Snyder, Gortler, Hoppe, "Texture mapping progressive meshes"
// (SIGGRAPH 2001): the singular values of the Jacobian of UV -> 3D.
//
// Inputs:  the triangle's corners in 3D and in UV.
// Output:  3D area, signed UV area, squared L2 stretch (mean squared singular
//          value) and the largest singular value; both stretches are 0 for a
//          UV-degenerate triangle (the caller counts it as flipped).
#pragma once

#include <array>

#include "soupuv/vec.h"

namespace soupuv::atlas {

struct TriangleStretch {
  double area3d = 0, area_uv = 0;
  double l2_squared = 0;
  double gamma_max = 0;
};

TriangleStretch triangle_stretch(const std::array<Vec3, 3>& q, const std::array<Vec2, 3>& p);

// The triangle laid flat in its own plane: first corner at the origin, second
// on the +x axis. Isometric to q.
std::array<Vec2, 3> flatten_triangle(const std::array<Vec3, 3>& q);

}  // namespace soupuv::atlas
