// Seam weights for the proxy's atlas: how many soup pairs a chart seam through
// each proxy face would cut, relative to the mean.
//
// Inputs:  the soup and the proxy mesh (the field never looks at the proxy,
//          but the atlas may look at the soup: seams are where the texture
//          breaks, and a seam of length L breaks about L * (soup edge length
//          per area) originally adjacent pairs).
// Output:  one weight per proxy face, > 0, area-weighted mean 1, clamped to
//          [0.05, 20]; for AtlasOptions::seam_weight.
//
// Method: each proxy face's centroid finds its closest soup point (BVH); the
// soup triangles whose boxes overlap a cube of one proxy edge length around
// that point give the local density sum(perimeter / 2) / sum(area) (edge
// length per area, shared edges counted once; summing before dividing keeps
// slivers from dominating). A line of length L crosses about (2 / pi) * L *
// density edges, so the weight is that density over its mean.
// Cost: O(F log T) for F proxy faces and T soup triangles.
#pragma once

#include <vector>

#include "soupuv/mesh.h"
#include "soupuv/soup.h"

namespace soupuv {

std::vector<double> soup_seam_weights(const Soup& soup, const TriMesh& proxy, int threads);

}  // namespace soupuv
