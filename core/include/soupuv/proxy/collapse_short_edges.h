// Short-edge collapse that keeps a closed 2-manifold closed and 2-manifold.
//
// Input:  a closed, oriented 2-manifold TriMesh (marching cubes / tetrahedra output),
//         min_edge_length, max_edge_length.
// Output: the mesh with edges collapsed roughly shortest-first (sweeps with a
//         threshold growing by 1.25), each to its midpoint,
//         until no collapsible edge is shorter than min_edge_length; the
//         topology (closedness, orientation, Euler characteristic of every
//         component) is unchanged. A collapse is refused when it would
//           - break the link condition (the one-rings of the two ends share
//             more than the two opposite vertices): the surface would pinch;
//           - turn a face over or make it degenerate (normal check against
//             the face before the collapse);
//           - create an edge longer than max_edge_length (keeps triangles
//             near the target size instead of growing long slivers).
// Why our own and not CGAL's: marching cubes emit millions of tiny triangles
// (about 2 per cell); collapsing them with plain arrays in about a dozen
// sweeps in face order is O(n) and many times faster than CGAL's heap on a
// halfedge structure, so CGAL's remeshing only sees the small result.
// Stats say how many collapses were done and refused, per reason.
#pragma once

#include <cstddef>

#include "soupuv/mesh.h"

namespace soupuv::proxy {

struct CollapseStats {
  size_t collapses = 0;
  size_t refused_link = 0, refused_flip = 0, refused_long = 0;
};

TriMesh collapse_short_edges(const TriMesh& mesh, double min_edge_length, double max_edge_length,
                             CollapseStats* stats = nullptr);

}  // namespace soupuv::proxy
