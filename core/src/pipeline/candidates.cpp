#include "pipeline/candidates.h"

namespace soupuv::pipeline {

bool candidate_search_runs(size_t triangles, double soup_per_proxy_face, const MapOptions& options) {
  if (options.candidates.size() < 2) return false;
  if (triangles > options.candidates_max_triangles) return false;
  return options.relax_max_soup_per_proxy_face <= 0 ||
         soup_per_proxy_face <= options.relax_max_soup_per_proxy_face;
}

bool candidate_admissible(const CandidateFigures& f, const MapOptions& options) {
  return f.flipped_fraction <= options.candidate_max_flipped &&
         f.stretch_l2 <= options.candidate_max_stretch_l2;
}

size_t choose_candidate(const std::vector<CandidateFigures>& figures, const MapOptions& options) {
  size_t best = 0;
  bool found = false;
  for (size_t i = 0; i < figures.size(); ++i) {
    if (!candidate_admissible(figures[i], options)) continue;
    // Strictly greater: a tie keeps the earlier candidate.
    if (!found || figures[i].continuity > figures[best].continuity) best = i;
    found = true;
  }
  return best;
}

nlohmann::json candidates_json(const std::vector<CandidateFigures>& figures, size_t chosen,
                               const MapOptions& options) {
  nlohmann::json list = nlohmann::json::array();
  for (size_t i = 0; i < figures.size(); ++i) {
    const CandidateFigures& f = figures[i];
    list.push_back({{"name", f.name},
                    {"continuity_weld", f.continuity},
                    {"flipped_fraction", f.flipped_fraction},
                    {"stretch_l2", f.stretch_l2},
                    {"charts", f.charts},
                    {"seconds", f.seconds},
                    {"proxy_rebuilt", f.proxy_rebuilt},
                    {"admissible", candidate_admissible(f, options)},
                    {"chosen", i == chosen}});
    if (f.island_relaxed >= 0)
      list.back()["island_relax"] = {{"relaxed", f.island_relaxed},
                                     {"stretch_l2_before", f.island_l2_before},
                                     {"largest", f.island_largest}};
  }
  return list;
}

}  // namespace soupuv::pipeline
