// Parametric test shapes (closed, outward-oriented meshes) used by tests and
// benchmarks of every stage, and the conversion from a mesh to a soup.
#pragma once

#include "soupuv/mesh.h"
#include "soupuv/soup.h"

namespace soupuv::shapes {

// UV sphere with `rings` latitude bands and `segments` longitude segments:
// 2*segments*(rings-1) triangles.
TriMesh uv_sphere(double radius, int rings, int segments);

// Geodesic sphere: icosahedron subdivided `level` times (20*4^level triangles),
// near-uniform triangle areas.
TriMesh icosphere(double radius, int level);

// Sphere with about `triangles` triangles of near-uniform area (a UV sphere
// whose rings x segments is chosen to match).
TriMesh sphere_with(double radius, int triangles);

// Torus around the z axis: major radius R, minor radius r, n x m quads split
// into 2*n*m triangles.
TriMesh torus(double R, double r, int n, int m);

// Torus with about `triangles` triangles: s x s quads when triangles = 2s^2,
// else 2m x m (the paper's resolutions 800 ... 204,800 are all one or the other).
TriMesh torus_with(double R, double r, int triangles);

// Axis-aligned cube of side `size` centred at the origin, each face an
// n x n grid of quads: 12*n*n triangles.
TriMesh cube(double size, int n);

// An open n x n grid of quads on the plane through `origin` spanned by u and
// v (each from -1 to 1), two triangles per quad, facing u x v.
TriMesh plane_grid(Vec3 origin, Vec3 u, Vec3 v, int n);

// Closed cylinder (radius, height along z, centred), with `segments` around,
// `stacks` along the side and fan-free capped ends made of rings.
TriMesh cylinder(double radius, double height, int segments, int stacks, int cap_rings);

// Open pipe (tube without caps), radius, height, segments around, stacks along.
TriMesh pipe(double radius, double height, int segments, int stacks);

// Every triangle gets its own three vertices (the paper's soup protocol, §10,
// without noise). noise > 0 then moves every vertex by uniform noise of up to
// noise * bounding-box diagonal per coordinate (deterministic for a seed).
Soup to_soup(const TriMesh& mesh, double noise = 0.0, unsigned seed = 1);

// Concatenate soups (origins renumbered by mesh index).
Soup merge(const Soup& a, const Soup& b);

// Translate / scale a mesh in place.
void translate(TriMesh& mesh, Vec3 offset);

}  // namespace soupuv::shapes
