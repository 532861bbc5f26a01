// The proxy and atlas parameters the field method asks for (pipeline.h says
// why they differ from the stages' own defaults). Kept apart from run_map so
// the atlas/proxy tuning and the pipeline's orchestration change separately.
#include "soupuv/pipeline.h"

namespace soupuv {

atlas::AtlasOptions map_atlas_defaults() {
  atlas::AtlasOptions o;
  // 90 is refused by the atlas; 70 vs 40 measured in pipeline.h.
  o.max_normal_deviation_deg = 70;
  // Measured choice: docs/tuning.md, "o.merge_charts".
  o.merge_charts = true;
  o.merge_max_area_fraction = 1;
  o.merge_min_fill = 0;
  o.merge_max_normal_deviation_deg = 120;
  // Measured choice: docs/tuning.md, "o.relax_seams".
  o.relax_seams = true;
  o.relax_band = 0.6;
  // Measured choice: docs/tuning.md, "o.alternative_normal_deviations_deg".
  o.alternative_normal_deviations_deg = {75, 85, 60};
  // The proxy atlas's layout is not the output's (the soup UV solve packs
  // the soup's islands itself): the column packer alone lays the charts out,
  // without the bitmap packer's turns and scale search, which were most of
  // the atlas's time (docs/tuning.md, "The proxy atlas's packing").
  o.pack_angles = 0;
  // Its layout only gives the atlas's scale (uv_per_length) and keeps the
  // charts apart, so it is packed at 512 texels with 1 texel of padding (the
  // same gap as 4 at 2048): the packing grid is 16x smaller, the pack 0.5-1.3
  // s -> 0.02-0.13 s, maps within +-0.001 continuity (docs/tuning.md, "The
  // proxy atlas packed at 512 texels, session 37").
  o.texture_size = 512;
  o.padding_px = 1;
  // Tried and not taken (session 6): docs/tuning.md, "Not taken".
  return o;
}

proxy::ProxyOptions map_proxy_defaults() {
  proxy::ProxyOptions o;
  // Measured choice: docs/tuning.md, "o.ladder".
  o.ladder = {0.03, 0.05, 0.08, 0.12};
  return o;
}

}  // namespace soupuv
