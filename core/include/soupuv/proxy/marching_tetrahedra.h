// Marching tetrahedra on the narrow band: the level set f = 0 as a welded,
// closed, 2-manifold, outward-oriented triangle mesh.
//
// Input:  a NarrowBand (leaf cells + f at their corners).
// Output: TriMesh; normals point from f < 0 (near the soup) to f >= 0.
// Why tetrahedra: every cube is split into the same six Kuhn (Freudenthal)
// tetrahedra around its main diagonal, which tiles space consistently and has
// no ambiguous cases, so the piecewise-linear level set is a closed 2-manifold
// for every sign pattern (f == 0 counts as outside: a symbolic perturbation).
// Vertices sit on grid edges, keyed by edge, so neighbouring cells share them;
// they are kept a small fraction away from the edge ends, so no triangle is
// degenerate and no two vertices coincide. Triangles of different
// tetrahedra meet only along shared faces: no self-intersections.
#pragma once

#include "soupuv/mesh.h"
#include "soupuv/proxy/narrow_band.h"

namespace soupuv::proxy {

TriMesh marching_tetrahedra(const NarrowBand& band, Progress& progress);

}  // namespace soupuv::proxy
