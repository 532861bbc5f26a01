// Bitmap (raster) packing of flattened charts into the unit square.
//
// Inputs:  charts        per chart its UVs (units of 3D length, one density for
//                        all), triangles and boundary loop (charts are disks).
//          texture_size  texels per side; padding_px  the gap between charts.
//          scale_to_beat texels per UV unit another packer already reached
//                        (0: none); only a denser packing is kept.
// Output:  when a denser packing was found, the UVs rewritten into [0,1]^2
//          (every chart turned, scaled by the common scale and moved by whole
//          texels) and that scale; otherwise the UVs are left unchanged and
//          the scale is 0.
//
// Method: every chart is rasterised conservatively at the trial scale in
// `angles` turns (multiples of 360/angles degrees from its current pose, the
// minimal-area rectangle's); in a fixed order (largest area or longest side
// first) each chart goes where one of its turns fits with the lowest
// bottom row + w * its height (w = 1: lowest top, the skyline rule; 0.5),
// then leftmost, among the charts already placed, each of them stored dilated by the padding, so charts never
// overlap and keep the padding by construction. Occupancy is kept per texel
// row as signed run lengths (free texels to the right > 0, occupied < 0):
// one lookup tells whether a chart's row interval fits, and a misfit tells how
// far right the next chance lies, so a search jumps over whole obstacles. A
// strip twice the square's height measures how much height a trial scale
// needs; the next scale is guessed from it (sqrt of the height ratio) and the
// bracket between the largest scale that fit and the smallest that did not
// shrinks until `precision`. Four greedy variants (two orders, two w) each
// try to beat the best scale so far; the largest scale that fit wins.
// With pilot_charts, the few largest charts, which decide how high a
// packing stacks, are each given the turn after which the greedy places
// the next three large ones lowest, before the greedy places the rest.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "pack.h"  // relative: the tests include this header by path

namespace soupuv::atlas {

struct RasterPackOptions {
  int angles = 16;           // turns tried per chart
  double precision = 1.003;  // stop when the scale bracket is this narrow
  int max_packings = 9;      // packings the first variant's scale search may spend
  int variant_packings = 3;  // and each further variant

  // The largest charts (at most this many, each at least 1 % of the area)
  // are placed by a pilot rule instead of the greedy's: each takes the turn
  // after which the greedy stacks the next three large charts lowest. 0: off.
  int pilot_charts = 0;

  // Charts below this share of the total area try small_chart_angles
  // quarter turns (at most 4; angles must be a multiple of 4) from the pose
  // with their minimal-area rectangle's axis along x, instead of `angles`
  // turns from their own pose. 0: every chart tries every turn.
  double small_chart_share = 0;
  int small_chart_angles = 0;

  int threads = 1;

  // Charts whose shape depends on the scale: before each packing, and
  // before the kept one is written, at_scale(scale) rewrites the UVs of the
  // charts marked in `elastic` in place (groups of small islands kept a
  // number of texels apart, whatever the scale); their areas must not
  // change. Null: every chart is rigid.
  std::function<void(double scale)> at_scale;
  const std::vector<uint8_t>* elastic = nullptr;
};

struct RasterPackResult {
  double scale = 0;  // texels per UV unit, 0 if nothing denser than scale_to_beat fit
  int attempts = 0;  // packings tried
};

// Texture sizes above 4096 are not rasterised (the occupancy would take
// hundreds of megabytes): the result is then scale 0.
RasterPackResult raster_pack(std::vector<PackChart>& charts, int texture_size, double padding_px,
                             double scale_to_beat, const RasterPackOptions& options);

}  // namespace soupuv::atlas
