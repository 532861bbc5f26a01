// Self-intersection test of a triangle mesh (CGAL Polygon Mesh Processing,
// box intersection + exact predicates), behind a plain interface.
//
// Input:  an oriented 2-manifold TriMesh (else Error{invalid_input}).
// Output: true when two non-adjacent faces intersect, or two adjacent faces
//         overlap beyond their shared edge / vertex.
#pragma once

#include "soupuv/mesh.h"

namespace soupuv::cgal {

bool self_intersects(const TriMesh& mesh);

}  // namespace soupuv::cgal
