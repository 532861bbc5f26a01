// Seam relaxation: the boundary between two neighbouring flattened charts
// moves to the cheapest cut inside a band around it, where a seam's cost is
// its length weighted by the faces it runs between (the pipeline weighs a
// proxy face by how many soup edges a seam through it would cut).
//
// Inputs:  the mesh, its topology, forced seam flags per edge (never moved,
//          never crossed by the band), the flattened charts, chart id per face
//          (updated), the face_local scratch of extract_chart, per-face seam
//          weights (empty = 1 everywhere), options.
// Output:  the charts after relaxation, each still a disk whose UVs pass the
//          same tests as any chart (no flip, no boundary self-intersection,
//          L2 stretch within max_stretch), and counts of what changed.
//
// Method: for a pair of charts A, B the band is every face of A or B within
// band_fraction * sqrt(area of the smaller chart) of their shared boundary
// (Dijkstra over face centroids). Faces of A outside the band are tied to the
// source, of B to the sink, and every edge between two faces of A or B that
// touches the band gets capacity length * (w_f + w_g) / 2. The minimum cut
// (max_flow.h) is the cheapest A/B boundary that keeps both cores; it is
// never dearer than the current one, which is one of the cuts. The pair is
// relabelled and both charts are flattened again; the new pair is kept only
// when both are disks that flatten validly, their joint L2 stretch rising by
// at most max_stretch_increase; otherwise the pair is retried
// with half the band. Disjoint pairs run in parallel; rounds repeat while
// some pair improves.
#pragma once

#include <vector>

#include "atlas/flat_split.h"
#include "atlas/mesh_topology.h"
#include "soupuv/mesh.h"

namespace soupuv::atlas {

struct RelaxOptions {
  double max_stretch = 1.05;
  int arap_iterations = 10;
  double band_fraction = 0.35;
  // A pair is relabelled only when the cut saves at least this fraction of
  // its current weighted boundary (re-flattening costs; tiny wins are noise).
  double min_gain = 0.02;
  // The pair's L2 stretch (area-weighted RMS of its two charts) may rise by
  // at most this: a cut can move into a region that flattens worse, and the
  // soup wears every bit of the atlas's stretch.
  double max_stretch_increase = 0.02;
  // A pair whose new charts do not both flatten is retried with the band
  // halved, up to this many times.
  int narrowings = 2;
  int rounds = 6;
  int threads = 1;
};

struct RelaxStats {
  int pairs_tried = 0;
  int pairs_relaxed = 0;     // kept: both charts flattened validly
  int faces_moved = 0;
  double cost_before = 0;    // weighted seam length between charts (not forced seams)
  double cost_after = 0;
};

// Weighted length of every edge between two charts: edge length times the
// mean weight of its two faces (weight 1 when `face_weight` is empty).
double weighted_seam_length(const MeshTopology& topology, const std::vector<int>& face_chart,
                            const std::vector<double>& face_weight);

RelaxStats relax_seams(const TriMesh& mesh, const MeshTopology& topology,
                       const std::vector<char>& forced_seam, std::vector<FlatChart>& charts,
                       std::vector<int>& face_chart, std::vector<int>& face_local,
                       const std::vector<double>& face_weight, const RelaxOptions& options);

}  // namespace soupuv::atlas
