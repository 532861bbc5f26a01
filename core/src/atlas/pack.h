// Packing of flattened charts into the unit square: the column packer below
// and, through raster_pack.h, the bitmap packer (alone for more than 64
// charts, else both and the denser layout wins).
//
// Inputs:  per chart its UVs (in units of 3D length: one density for all) and
//          triangles and boundary loop, the texture size and the padding in
//          texels.
// Output:  the UVs rewritten in [0,1]^2 (every chart scaled by the same
//          uv_per_length, rotated and translated), with at least padding_px
//          texels between any two charts.
//
// Method: each chart is turned to its minimal-area bounding rectangle
// (the best hull edge direction), then charts are placed one by one on a
// grid of columns about 4 texels wide and rows one texel tall: each chart, in
// four quarter turns (and, with few charts, also turned by 30 and 60
// degrees), becomes one run of rows per column (dilated by half the padding),
// and goes where bottom + w * height is lowest among all columns and turns
// (w = 1: lowest top). Columns keep signed free/occupied run lengths, so a
// chart can also drop into a hole between earlier charts, and the search for
// the lowest fit jumps over whole occupied runs. The common scale comes from
// a few packings into a tall strip, each rescaled by sqrt(square height /
// height used); then a portfolio of greedy variants (two orders, three values
// of w, the turned poses) each tries to fit at a larger scale, and the
// largest scale that fits wins. Only if that fills less than 70% does a
// second pass retry the winning variant with the turned poses and a finer
// scale search.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "soupuv/vec.h"

namespace soupuv::atlas {

struct PackChart {
  std::vector<Vec2>* uv;
  const std::vector<std::array<int, 3>>* triangles;
  const std::vector<int>* outline;  // the boundary loop (charts are disks)
  // Instead of `outline` (null), for raster_pack only: the chart's boundary
  // edges as vertex pairs, for islands that are not disks.
  const std::vector<std::array<int, 2>>* boundary = nullptr;
};

struct PackResult {
  std::string method;      // "columns" or "raster": which packer's layout won
  double uv_per_length = 0;
  double utilization = 0;  // UV area / 1
  int attempts = 0;        // packings tried by the scale search
};

// Minimal-area bounding rectangle of a point set (one side is parallel to a
// convex hull edge): the unit direction of its first side and its size along
// that side and across.
struct MinRectangle {
  Vec2 axis;
  Vec2 size;
};
MinRectangle min_area_rectangle(const std::vector<Vec2>& points);

// Throws Error{limit_exceeded} if the charts cannot fit at any scale (more
// charts than the padding leaves room for).
// The column portfolio runs first; then the bitmap packer (raster_pack.h,
// with `raster`'s settings) tries to beat its scale, and the denser layout is
// kept.
struct RasterPackOptions;
PackResult pack_charts(std::vector<PackChart>& charts, int texture_size, double padding_px,
                       const RasterPackOptions& raster);

}  // namespace soupuv::atlas
