// Forwarding header for core/src/uvsolve only: welding moved to
// soupuv/geometry/weld.h (issue 23), and the UV solve, changed in parallel by
// another engineer, still includes this path and says quality::Weld. Delete
// this file once uvsolve includes soupuv/geometry/weld.h; nothing else may
// include it.
#pragma once

#include "soupuv/geometry/weld.h"

namespace soupuv::quality {
using geometry::AdjacentPair;
using geometry::edge_adjacency;
using geometry::Weld;
}  // namespace soupuv::quality
