// Welds of the soup through the content-addressed cache. A weld depends on
// the soup's geometry and its own tolerances alone, never on the proxy or
// the atlas, so a re-run with a new offset reads it back instead of welding
// 100k triangles again (100k torus: edge weld ~0.5 s, the repair's strict
// retry weld as much again).
//
//   cached_weld(store, soup_hash, recipe, compute, hit)
//     store      the run's cache (nullptr: compute and return)
//     soup_hash  geometry_hash(soup)
//     recipe     everything compute depends on besides the soup, as text
//                (the weld's kind and its parameters)
//     compute    builds the weld on a miss
//   -> the weld; hit says whether it came from the store.
#pragma once

#include <functional>
#include <string>

#include "soupuv/geometry/weld.h"

namespace soupuv::cache { class Store; }

namespace soupuv::pipeline {

geometry::Weld cached_weld(cache::Store* store, const std::string& soup_hash, const std::string& recipe,
                          const std::function<geometry::Weld()>& compute, bool& hit);

// "name a=1.2345 b=..." with every number at full precision, for recipes.
std::string weld_recipe(const std::string& kind, std::initializer_list<double> parameters);

}  // namespace soupuv::pipeline
