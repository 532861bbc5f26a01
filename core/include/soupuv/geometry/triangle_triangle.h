// Do two triangles cut each other? (Paper §12.1: the refinement of
// intersecting soup triangles asks it of every pair whose boxes overlap.)
//
//   triangles_intersect(a, b) -> true when the triangles share a segment of
//     positive length: each triangle's crossing of the other's plane is an
//     interval on the planes' common line, and the two intervals overlap.
//     Parallel and coplanar pairs are reported as not cutting (a coplanar
//     overlap does not separate anything to refine).
#pragma once

#include <array>

#include "soupuv/vec.h"

namespace soupuv::geometry {

bool triangles_intersect(const std::array<Vec3, 3>& a, const std::array<Vec3, 3>& b);

}  // namespace soupuv::geometry
