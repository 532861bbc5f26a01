// Taubin lambda|mu smoothing (Taubin 1995): alternating a shrinking Laplacian
// step (lambda > 0) and an inflating one (mu < -lambda) removes high-frequency
// noise without the shrinkage of plain Laplacian smoothing (paper Fig. 4 right).
//
// Input:  a mesh (connectivity is never changed), iterations, lambda, mu.
// Output: the mesh with moved vertices (umbrella operator, uniform weights).
#pragma once

#include "soupuv/mesh.h"

namespace soupuv::proxy {

void taubin_smooth(TriMesh& mesh, int iterations, double lambda = 0.5, double mu = -0.53);

}  // namespace soupuv::proxy
