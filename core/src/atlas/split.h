// Splitting one chart in two, for charts that are not disks or cannot be
// flattened cleanly.
//
// Inputs:  topology, forced seams, the chart's faces (face-connected through
//          non-seam edges) and chart id per face.
// Output:  the two halves (each non-empty and face-connected when the chart
//          has at least two faces): a geodesic Voronoi split of the face graph
//          from two far-apart seeds, found by two Dijkstra sweeps over face
//          centroid distances. A ring becomes two arcs, so handles and holes
//          disappear after enough splits.
#pragma once

#include <array>
#include <vector>

#include "atlas/mesh_topology.h"

namespace soupuv::atlas {

std::array<std::vector<int>, 2> split_chart(const MeshTopology& topology,
                                            const std::vector<char>& forced_seam,
                                            const std::vector<int>& faces,
                                            const std::vector<int>& face_chart);

}  // namespace soupuv::atlas
