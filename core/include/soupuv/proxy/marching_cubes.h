// Marching cubes on the narrow band with a face-consistent ambiguity rule: the
// level set f = 0 as a welded, closed, 2-manifold, outward-oriented mesh with
// about 2 triangles per cell (marching tetrahedra make about 6).
//
// Input:  a NarrowBand (leaf cells + f at their corners).
// Output: TriMesh; normals point from f < 0 (near the soup) to f >= 0
//         (f == 0 counts as outside: a symbolic perturbation).
// How, and why it is closed: no case table. On each of a cell's six faces the
// crossing points of its sign-changing edges are joined by segments; a face
// with two diagonally opposite inside corners is ambiguous and decided by the
// asymptotic decider — the sign of the face's bilinear interpolant at its
// saddle, f0 f2 - f1 f3 compared exactly in a form that does not depend on
// the corner order — so the two cells sharing a face draw the same segments.
// The segments of a cell form closed loops on its boundary (every crossing
// point ends one segment on each of its edge's two faces); each loop becomes
// a triangle, a quad split along its shorter diagonal, or a fan around its
// centroid. Every segment is then an edge of exactly one triangle on each
// side of the face: closed and 2-manifold for every sign pattern. Interior
// ambiguities (tunnels through a cell) are not resolved trilinearly; the
// face rule alone already decides a consistent topology.
// Vertices sit on grid edges a small fraction away from the corners, so no
// triangle is degenerate and no two vertices coincide.
#pragma once

#include "soupuv/mesh.h"
#include "soupuv/proxy/narrow_band.h"

namespace soupuv::proxy {

TriMesh marching_cubes(const NarrowBand& band, Progress& progress);

}  // namespace soupuv::proxy
