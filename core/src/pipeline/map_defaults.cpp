// The proxy and atlas parameters the field method asks for (pipeline.h says
// why they differ from the stages' own defaults). Kept apart from run_map so
// the atlas/proxy tuning and the pipeline's orchestration change separately.
#include "soupuv/pipeline.h"

namespace soupuv {

atlas::AtlasOptions map_atlas_defaults() {
  atlas::AtlasOptions o;
  // 90 is refused by the atlas; 70 vs 40 measured in pipeline.h.
  o.max_normal_deviation_deg = 70;
  return o;
}

proxy::ProxyOptions map_proxy_defaults() {
  proxy::ProxyOptions o;
  o.ladder = {0.03, 0.05, 0.08, 0.12};
  return o;
}

}  // namespace soupuv
