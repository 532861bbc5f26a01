// The tri-planar box projection that modelling tools offer ("cube projection"):
// the paper's §11 comparison baseline and soupuv's `--method box`.
//
// Input : a soup (any triangles; degenerate ones get face +x).
// Output: 3 UVs per triangle (glTF convention: origin at the image's top-left,
//         v pointing down). Each triangle is projected along the axis its
//         normal is most aligned with onto one of the 6 faces of the soup's
//         bounding cube; the 6 face images are laid out in a 3x2 grid of
//         [0,1]^2 (columns x, y, z; top row the + faces, bottom row the - faces),
//         each in a square cell inset by `padding`, one common scale for all so
//         that texel density is uniform. Each face is seen from outside, so
//         front-facing triangles keep their orientation.
// Cost  : O(triangles).
#pragma once

#include <array>
#include <vector>

#include "soupuv/progress.h"
#include "soupuv/soup.h"

namespace soupuv::baseline {

struct BoxOptions {
  double padding = 0.01;  // gap around each face image, in UV units
};

struct BoxResult {
  std::vector<Vec2> corner_uvs;          // 3 per triangle
  std::array<size_t, 6> face_triangles{};  // triangles per face: +x +y +z -x -y -z
  double seconds = 0;
};

BoxResult box_projection(const Soup& soup, const BoxOptions& options = {},
                         Progress& progress = Progress::none());

}  // namespace soupuv::baseline
