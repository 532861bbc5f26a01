// Choosing among (proxy, atlas) candidates by measured quality. The field
// does not depend on the proxy or the atlas (§9), so on small soups run_map
// lands the one field on every candidate of MapOptions::candidates and keeps
// the best; these are the rules it follows.
//
//   candidate_search_runs(triangles, soup_per_proxy_face, options)
//     -> true when the soup is small and coarse enough for the search (the
//        big soups keep one run and their run time).
//   choose_candidate(figures, options)
//     figures  per candidate, in list order: continuity by the WELD-inferred
//              adjacency (never the --original reference, which would let the
//              choice see the answer), flipped fraction, L2 stretch
//     -> the index of the highest continuity among the candidates within
//        MapOptions::candidate_max_flipped and candidate_max_stretch_l2; ties
//        go to the earlier one; 0 (the run's own options) when none is
//        within them.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "soupuv/pipeline.h"

namespace soupuv::pipeline {

struct CandidateFigures {
  std::string name;
  double continuity = 0;  // weld-inferred adjacency
  double flipped_fraction = 0;
  double stretch_l2 = 0;
  int charts = 0;
  double seconds = 0;  // proxy (when rebuilt) + atlas + transfer + repair + measure
  bool proxy_rebuilt = false;
  // The island relaxation's relaxed islands and the map's L2 before it
  // (-1: it did not run).
  long island_relaxed = -1;
  double island_l2_before = 0;
  nlohmann::json island_largest;  // the three largest islands: triangles, outcome, L2 before / after
};

bool candidate_search_runs(size_t triangles, double soup_per_proxy_face, const MapOptions& options);

bool candidate_admissible(const CandidateFigures& f, const MapOptions& options);

size_t choose_candidate(const std::vector<CandidateFigures>& figures, const MapOptions& options);

// atlas.candidates: one object per candidate, the chosen one marked.
nlohmann::json candidates_json(const std::vector<CandidateFigures>& figures, size_t chosen,
                               const MapOptions& options);

}  // namespace soupuv::pipeline
