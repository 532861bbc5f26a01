// The offset-surface proxy: the proxy branch's result that atlas/ and
// transfer/ read. Contract: keep these fields; add to them rather than change.
#pragma once

#include <vector>

#include "soupuv/mesh.h"

namespace soupuv::proxy {

struct ProxyMesh {
  TriMesh mesh;                 // closed, 2-manifold, outward, outer components only
  std::vector<int> face_component;  // outer component id per face
  int outer_components = 0;
  double offset = 0;            // absolute offset length used
  int resolution = 0;           // voxels along the longest axis
};

}  // namespace soupuv::proxy
