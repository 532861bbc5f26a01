// Segmentation of a closed mesh into charts of nearly one normal direction.
//
// Inputs:  topology (edge adjacency, face normals and areas), forced_seam (per
//          edge id: 1 if the flood must not cross it), max_deviation_deg (the
//          budget: largest angle between a face normal and its chart's mean).
// Output:  chart id per face, 0 .. count-1; every chart is face-connected
//          through non-seam edges.
//
// Method: variational shape approximation (Cohen-Steiner et al. 2004, L2,1
// metric) by Lloyd iterations: charts are flooded from seeds in order of
// area * |n_f - N_chart|^2, seeds move to the best-fitting face, and every chart
// whose worst face breaks the budget gets a new seed there, until none does.
// The metric makes boundaries land on creases, and the chart count follows
// the budget rather than a fixed number.
#pragma once

#include <vector>

#include "atlas/mesh_topology.h"
#include "soupuv/progress.h"

namespace soupuv::atlas {

struct Segmentation {
  std::vector<int> face_chart;
  int count = 0;
  int rounds = 0;
};

Segmentation segment_charts(const MeshTopology& topology, const std::vector<char>& forced_seam,
                            double max_deviation_deg, Progress& progress);

}  // namespace soupuv::atlas
