// Quality figures of a finished atlas (paper §6, issue 5 diagnostics).
//
// Inputs:  the mesh and its atlas (per-face corner UVs).
// Output:  area-weighted L2 stretch and L-infinity stretch (Sander et al.
//          2001), both multiplied by sqrt(UV area / 3D area) so that 1 means
//          isometric up to one global scale; mean absolute corner angle change
//          in degrees; flipped faces; overlap as the fraction of covered texels
//          (centres sampled at texture_size^2) covered by more than one face;
//          utilisation as the UV area inside [0,1]^2.
#pragma once

#include "soupuv/atlas/atlas.h"
#include "soupuv/mesh.h"

namespace soupuv::atlas {

struct AtlasMetrics {
  double stretch_l2 = 0, stretch_linf = 0, angle_distortion_deg = 0;
  int flipped = 0;
  double overlap = 0, utilization = 0;
};

AtlasMetrics measure_atlas(const TriMesh& mesh, const Atlas& atlas);

// Fraction of covered texel centres covered by two or more faces; exposed for
// tests.
double raster_overlap(const std::vector<std::array<Vec2, 3>>& face_uvs, int resolution);

}  // namespace soupuv::atlas
