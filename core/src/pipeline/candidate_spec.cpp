// parse_map_candidate: the text form of a MapCandidate (pipeline.h) that the
// CLI's --candidate and the benches take.
#include <sstream>

#include "soupuv/errors.h"
#include "soupuv/pipeline.h"

namespace soupuv {

MapCandidate parse_map_candidate(const std::string& spec) {
  MapCandidate c{"", map_atlas_defaults(), 0};
  const size_t colon = spec.find(':');
  c.name = spec.substr(0, colon);
  if (c.name.empty()) throw Error(ErrorCode::invalid_input, "a candidate needs a name: " + spec);
  if (colon == std::string::npos) return c;
  std::stringstream list(spec.substr(colon + 1));
  std::string item;
  while (std::getline(list, item, ',')) {
    const size_t eq = item.find('=');
    if (eq == std::string::npos) throw Error(ErrorCode::invalid_input, "candidate item without '=': " + item);
    const std::string key = item.substr(0, eq);
    double value = 0;
    try {
      size_t used = 0;
      value = std::stod(item.substr(eq + 1), &used);
      if (used != item.size() - eq - 1) throw std::invalid_argument("trailing text");
    } catch (const std::exception&) {
      throw Error(ErrorCode::invalid_input, "candidate item needs a number: " + item);
    }
    atlas::AtlasOptions& a = c.atlas;
    if (key == "angle") a.max_normal_deviation_deg = value;
    else if (key == "alt_angle") a.alternative_normal_deviations_deg.push_back(value);
    else if (key == "no_alt_angles") a.alternative_normal_deviations_deg.clear();
    else if (key == "stretch") a.max_stretch = value;
    else if (key == "merge") a.merge_charts = value != 0;
    else if (key == "merge_crease") a.merge_crease_deg = value;
    else if (key == "merge_cone") a.merge_max_normal_deviation_deg = value;
    else if (key == "merge_area") a.merge_max_area_fraction = value;
    else if (key == "merge_fill") a.merge_min_fill = value;
    else if (key == "merge_stretch") a.merge_max_stretch = value;
    else if (key == "merge_sweeps") a.merge_stretch_sweeps = int(value);
    else if (key == "pack_splits") a.packing_split_rounds = int(value);
    else if (key == "split_below") a.packing_split_below = value;
    else if (key == "relax") a.relax_seams = value != 0;
    else if (key == "relax_band") a.relax_band = value;
    else if (key == "relax_stretch") a.relax_max_stretch_increase = value;
    else if (key == "relax_narrow") a.relax_narrowings = int(value);
    else if (key == "soup_weights") a.soup_seam_weights = value != 0;
    else if (key == "offset") c.proxy_offset_fraction = value;
    else throw Error(ErrorCode::invalid_input, "unknown candidate key: " + key);
  }
  return c;
}

}  // namespace soupuv
