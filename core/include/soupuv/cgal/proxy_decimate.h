// Short-edge collapse of a closed proxy mesh (CGAL Surface_mesh_simplification),
// behind a plain interface so only core/src/cgal includes CGAL.
//
// Input:  a closed, oriented 2-manifold TriMesh and a length.
// Output: the mesh with its edges collapsed shortest-first (to their midpoints)
//         until none is shorter than `min_edge_length`. CGAL checks the link
//         condition, so the result stays a closed 2-manifold; collapses that
//         would turn a face over are refused (bounded normal change). Why:
//         marching tetrahedra make ~5 small triangles per cell, and remeshing
//         that many is what made the proxy slow; this cuts them to the target
//         size first. The caller verifies the result.
#pragma once

#include "soupuv/mesh.h"

namespace soupuv::cgal {

TriMesh collapse_short_edges(const TriMesh& mesh, double min_edge_length);

}  // namespace soupuv::cgal
