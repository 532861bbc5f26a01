// Lifts proxy vertices that sank below the offset back towards d = o.
//
// Input:  a closed, outward-oriented TriMesh (the smoothed proxy), the soup's
//         BVH, the offset o, a largest step, iterations.
// Output: the mesh with every vertex whose distance to the soup is below o
//         moved along its (area-weighted) outward normal by min(o - d, step),
//         repeated `iterations` times; vertices at or above o stay put.
// Why: edge collapse to midpoints and Taubin smoothing pull vertices inwards
// on the offset surface's creases (concave parts), down to about 0.55 o on
// suzanne; the field lines need the proxy to keep its distance (paper §5).
// Only lifting, never pulling in, and a bounded step keep the surface from
// folding; the caller re-measures every check anyway.
#pragma once

#include "soupuv/mesh.h"
#include "soupuv/geometry/distance_bvh.h"

namespace soupuv::proxy {

// Returns the smallest distance ratio d / o over the vertices after lifting.
double lift_to_offset(TriMesh& mesh, const geometry::DistanceBvh& soup_bvh, double offset, double max_step,
                      int iterations);

}  // namespace soupuv::proxy
