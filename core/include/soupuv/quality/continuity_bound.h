// An estimated upper bound on the continuity a low-distortion atlas can reach.
//
// Input : a soup, a weld of its corners (the metric's: the original's
//         vertices or a position weld) and its edge adjacency.
// Output: the cone vertices (interior vertices whose angle sum differs from
//         2 pi by more than cone_defect radians), the fewest seam edges any
//         flip-free, nearly isometric atlas must cut, and the bound
//         1 - cuts / adjacent pairs on the continuity figure.
// Why   : a flat chart cannot hold a cone vertex inside it without large
//         stretch, so every cone lies on a seam; the seams of a closed
//         component form a connected graph through all its cones (>= cones - 1
//         edges), those of an open one reach its border (>= cones edges), and
//         every cut edge breaks at least one adjacent pair. A cube's 12
//         triangles: 8 cones (deficit pi/2), 18 pairs, >= 7 cuts, bound 11/18.
//         Meaningless for large smooth meshes (bound ~1), telling for tiny ones.
// Caveat: an estimate, not a guarantee. A chart may take a mild cone with some
//         stretch, and a seam that ends at a cone can keep its pair within
//         the continuity tolerance: suzanne's soup (session 5, quiet) measures
//         0.951 against its 0.912. Exact for the cube (0.556 <= 11/18).
// Cost  : O(n) plus sorting the adjacency.
#pragma once

#include <cstddef>
#include <vector>

#include "soupuv/geometry/weld.h"
#include "soupuv/soup.h"

namespace soupuv::quality {

struct ContinuityBound {
  size_t cone_vertices = 0;
  size_t min_cut_edges = 0;
  size_t pairs = 0;
  double bound = 1;  // 1 when there are no pairs
};

ContinuityBound continuity_bound(const Soup& soup, const geometry::Weld& weld,
                                 const std::vector<geometry::AdjacentPair>& adjacency,
                                 double cone_defect = 0.7853981633974483 /* pi/4 */);

}  // namespace soupuv::quality
