// Chart merging under the distortion budget: fewer charts and shorter seams
// after segmentation and flattening (seams are where the pipeline's texture
// breaks).
//
// Inputs:  the mesh, its topology, forced seam flags per edge (never merged
//          across), the flattened charts (disks with valid UVs), chart id per
//          face (updated), the face_local scratch of extract_chart, options.
// Output:  the charts after merging (each still a disk whose UVs have no flip,
//          no boundary self-intersection and L2 stretch within max_stretch)
//          and the number of merges.
//
// Method: neighbouring charts are candidates when most of the boundary they
// share is smooth (dihedral angle below crease_deg: creases are good seams
// and stay); longest smooth shared boundary first, a greedy matching of
// candidates is tried in parallel per round: the union is cut out, checked to
// be a disk and flattened again (LSCM + ARAP); it replaces the pair only if
// that flattening passes the same tests as any chart (and the size, fill
// and normal-cone limits below). Rounds repeat on the
// merged charts until none merges; a failed pair is not tried again.
#pragma once

#include <vector>

#include "atlas/flat_split.h"
#include "atlas/mesh_topology.h"
#include "soupuv/mesh.h"

namespace soupuv::atlas {

struct MergeOptions {
  double max_stretch = 1.05;
  int arap_iterations = 10;
  int stretch_sweeps = 0;  // L2-stretch descent after ARAP (stretch_descent.h)
  double crease_deg = 60;
  // Big or ragged charts pack badly (a square of few large charts fills
  // little of it): a merge is refused when the union would hold more than
  // max_area_fraction of the surface, or fill less than min_fill of its
  // minimal-area rectangle in UV.
  double max_area_fraction = 1.0;
  double min_fill = 0.0;
  // Largest angle between a face normal of the union and the union's
  // area-weighted mean normal (degrees); 0 = no limit.
  double max_normal_deviation_deg = 0;
  int rounds = 12;
  int threads = 1;
};

int merge_charts(const TriMesh& mesh, const MeshTopology& topology, const std::vector<char>& forced_seam,
                 std::vector<FlatChart>& charts, std::vector<int>& face_chart,
                 std::vector<int>& face_local, const MergeOptions& options);

}  // namespace soupuv::atlas
