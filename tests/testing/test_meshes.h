// Closed test meshes for the atlas tests and benchmark beyond shapes.h:
// surfaces of higher genus and CAD-like parts, made by marching tetrahedra
// over an implicit function and a little Laplacian smoothing (like a proxy:
// a marched, smoothed, closed 2-manifold).
#pragma once

#include <functional>

#include "soupuv/mesh.h"

namespace soupuv::test_meshes {

// Closed surface f = 0 of a scalar field sampled on a grid of `cells` cells
// along the longest side of [lo, hi]; f < 0 inside. Faces are oriented
// outward. `smoothing` Laplacian passes move each vertex halfway to the mean
// of its neighbours (no shrink control: a handful of passes only).
TriMesh march(const std::function<double(Vec3)>& f, Vec3 lo, Vec3 hi, int cells, int smoothing);

// `genus` tori (R = 1, r = 0.4) fused in a row: a closed surface of that
// genus, about `triangles` faces (roughly; the grid is chosen from it).
TriMesh fused_tori(int genus, int triangles);

// A CAD-like block: a box 2 x 1.4 x 0.8 with a cylindrical hole through it and
// a cylindrical boss on top (sharp edges, genus 1), about `triangles` faces.
TriMesh drilled_block(int triangles);

}  // namespace soupuv::test_meshes
