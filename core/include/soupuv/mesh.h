// An indexed triangle mesh with shared vertices: the proxy, the test shapes,
// anything that is a surface rather than a soup.
#pragma once

#include <array>
#include <vector>

#include "soupuv/vec.h"

namespace soupuv {

struct TriMesh {
  std::vector<Vec3> vertices;
  std::vector<std::array<int, 3>> faces;  // counter-clockwise seen from outside
};

}  // namespace soupuv
