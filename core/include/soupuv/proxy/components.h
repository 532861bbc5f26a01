// Connected components of a closed mesh and which of them are inner (paper §5:
// cavities of the offset surface lie inside the outer component and are dropped).
//
// Input:  a closed, manifold, consistently oriented TriMesh.
// Output: a component id per face; per component whether it lies inside another
//         (bounding boxes first, then BVH ray parity of one vertex — components
//         of an extracted level set never cross, so one vertex decides).
#pragma once

#include <vector>

#include "soupuv/mesh.h"

namespace soupuv::proxy {

struct Components {
  std::vector<int> face_component;  // component id per face, 0 .. count-1
  int count = 0;
  std::vector<char> inner;          // per component: inside another component
  std::vector<double> volume;       // signed volume per component (> 0: outward)
};

Components find_components(const TriMesh& mesh);

// The mesh restricted to faces with keep[face] set, unreferenced vertices removed.
TriMesh keep_faces(const TriMesh& mesh, const std::vector<char>& keep);

// Signed volume enclosed by the faces with face_component == component (all
// faces when component < 0); positive for outward-oriented closed surfaces.
double signed_volume(const TriMesh& mesh, const std::vector<int>& face_component = {},
                     int component = -1);

}  // namespace soupuv::proxy
