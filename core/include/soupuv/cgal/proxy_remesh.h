// Isotropic remeshing of a closed proxy mesh (CGAL Polygon Mesh Processing),
// behind a plain interface so only core/src/cgal includes CGAL.
//
// Input:  a closed, manifold TriMesh, a target edge length, iterations.
// Output: the remeshed TriMesh (vertices projected back onto the input surface
//         by CGAL). The caller verifies the result; nothing here is assumed.
#pragma once

#include "soupuv/mesh.h"

namespace soupuv::cgal {

TriMesh isotropic_remesh(const TriMesh& mesh, double target_edge_length, int iterations);

}  // namespace soupuv::cgal
