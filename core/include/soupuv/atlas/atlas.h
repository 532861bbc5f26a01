// A UV atlas of a closed mesh: the atlas branch's result that the transfer
// stage reads. Contract between atlas/ and transfer/: keep these fields; add to
// them rather than change them.
#pragma once

#include <array>
#include <vector>

#include "soupuv/vec.h"

namespace soupuv::atlas {

struct Atlas {
  // UVs of each mesh face's three corners (per face, since a seam gives a
  // vertex several UVs), in [0,1]^2, glTF convention (v = 0 at the image top).
  std::vector<std::array<Vec2, 3>> face_uvs;
  std::vector<int> face_chart;   // chart id per face, 0 .. chart_count-1
  int chart_count = 0;
  int texture_size = 2048;       // texels along one side the packing aimed at
  double padding_px = 4;
  // UV units per unit of 3D length: one texel density for all charts.
  double uv_per_length = 0;
};

}  // namespace soupuv::atlas
