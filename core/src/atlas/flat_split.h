// Splitting an already flattened chart in two, for packing: a few large
// charts pack poorly (six cube faces fill at most 2/3 of a square), halves
// fill the gaps. The halves keep the parent's UVs, so they stay injective and
// need no new parameterization.
//
// Inputs:  the chart (disk, valid UVs in units of 3D length), mesh, topology,
//          forced seams, chart id per face (updated), the next free chart id
//          (advanced) and the face_local scratch of extract_chart.
// Output:  the two halves when the cut leaves two disks, else nothing (and
//          face_chart unchanged). The cut is straight in UV, across the
//          chart's longest principal direction at its area median.
#pragma once

#include <optional>
#include <utility>
#include <vector>

#include "atlas/chart_mesh.h"
#include "atlas/mesh_topology.h"

namespace soupuv::atlas {

struct FlatChart {
  ChartMesh mesh;
  std::vector<Vec2> uv;  // per local vertex
};

std::optional<std::pair<FlatChart, FlatChart>> split_flat_chart(
    const FlatChart& chart, const TriMesh& mesh, const MeshTopology& topology,
    const std::vector<char>& forced_seam, std::vector<int>& face_chart, int& next_id,
    std::vector<int>& face_local);

}  // namespace soupuv::atlas
