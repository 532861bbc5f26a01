// The proxy and atlas parameters the field method asks for (pipeline.h says
// why they differ from the stages' own defaults). Kept apart from run_map so
// the atlas/proxy tuning and the pipeline's orchestration change separately.
#include "soupuv/pipeline.h"

namespace soupuv {

atlas::AtlasOptions map_atlas_defaults() {
  atlas::AtlasOptions o;
  // 90 is refused by the atlas; 70 vs 40 measured in pipeline.h.
  o.max_normal_deviation_deg = 70;
  // Chart merging, without size or fill limits but within a 120 deg normal
  // cone (no chart wraps around a thin part): seams are what cut the texture
  // (every seam cuts ~ its length / soup edge length soup pairs), and merging
  // halves their length. Session 3's `--merge-charts` lowered continuity only
  // because the packing rounds halved the merged charts again (fixed in the
  // atlas: no packing splits when merging). Measured with the untangling UV
  // repair (88bb341), `soupuv-bench atlas-pipeline --variant pipeline
  // --variant c120:merge=1,merge_area=1,merge_fill=0,merge_cone=120`, loaded
  // machine; continuity / flipped % / L2 stretch, unmerged -> this:
  // suzanne 0.861/1.14/3.57 -> 0.906/1.14/3.47, spot 0.926/0/1.15 ->
  // 0.959/0/1.18, teapot 0.905/1.30/2.09 -> 0.935/1.30/1.61, fandisk
  // 0.959/0/1.18 -> 0.979/0.01/1.18, Duck 0.931/0.09/1.11 -> 0.968/0.02/1.17,
  // CesiumMan 0.904/0/1.21 -> 0.939/0/1.23, Fox 0.791/0/1.14 ->
  // 0.845/0/1.26; 3-9 charts instead of 15-34; the cost is utilisation
  // 0.64-0.67 instead of 0.72-0.75 (about 6 % fewer texels per length).
  // Unlimited merging (no cone) cuts seams further (suzanne 0.935, spot
  // 0.968, fandisk 0.986, Fox 0.903) but Fox's L2 goes 1.14 -> 1.53; the
  // session-3 limits (10 % of the surface, fill 0.5) give less and raised
  // the L2 tail with the older repair.
  o.merge_charts = true;
  o.merge_max_area_fraction = 1;
  o.merge_min_fill = 0;
  o.merge_max_normal_deviation_deg = 120;
  return o;
}

proxy::ProxyOptions map_proxy_defaults() {
  proxy::ProxyOptions o;
  // Tried with the merged atlas above (`soupuv-bench atlas-pipeline`,
  // variant keys offset / proxy_edge), no consistent gain, so not taken:
  // offset 0.05 continuity -0.009 .. +0.018 per sample, flips up on six of
  // seven; a finer remeshing edge (1.2 % of the diagonal instead of the
  // offset, ~6x the proxy triangles) continuity -0.003 .. -0.031, flips
  // down on five of seven (fandisk 0.76 -> 0.06 %), L2 erratic (both with
  // the older UV repair).
  o.ladder = {0.03, 0.05, 0.08, 0.12};
  return o;
}

}  // namespace soupuv
