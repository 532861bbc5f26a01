// Packs the layout's islands into the unit square (private to the UV solve)
// with the project's bitmap packer (atlas/raster_pack.h) at one texel
// density: islands are rasterised from their boundary edges (they need not
// be disks), turned, and placed so they never overlap and keep the padding.
// When there are more than 4,096, all but the 2,048 largest (unless longer
// than half a row of 1/8 the square's side) are first put side by side in
// rows, nested (nest_rows.h: each turned by 180 degrees where it sits
// closer), with a gap that keeps the padding at any scale the packer tries,
// and each group of 8 rows is packed as one piece: the packer's cost grows
// with the pieces, not their size.
//
// Input : the layout, the texture size and padding in texels, threads.
// Output: per soup triangle its corner UVs in [0,1]^2 and the packing's
//         scale (texels per UV unit) and utilisation (UV area / 1).
// Throws: Error{limit_exceeded} when the islands fit at no scale.
#pragma once

#include <array>
#include <vector>

#include "uvsolve/uv_layout.h"

namespace soupuv::uvsolve::detail {

struct PackFigures {
  double texels_per_uv = 0;
  double utilisation = 0;
  int attempts = 0;
  size_t units = 0;            // pieces the packer moved
  size_t grouped_islands = 0;  // small islands packed in rows first, as groups
};

// How hard the packer tries. thorough: a map of at most kThoroughMaxUnits
// pieces is packed as maps of many are, its largest pieces placed by the
// packer's pilot rule (atlas/raster_pack.h: each takes the turn after
// which the next three large ones stack lowest). Few-piece maps pack
// denser so, but it costs 0.2-1.5 s a map (docs/tuning.md, session 33):
// for maps that otherwise miss the utilisation target.
enum class PackEffort { normal, thorough };
// Above this many pieces every packing is made the thorough way already.
constexpr size_t kThoroughMaxUnits = 200;

PackFigures pack_islands(const UvLayout& layout, int texture_size, double padding_px, int threads,
                         std::vector<std::array<Vec2, 3>>& corner_uvs, PackEffort effort = PackEffort::normal);

}  // namespace soupuv::uvsolve::detail
