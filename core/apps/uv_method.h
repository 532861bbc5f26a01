// The one place where the CLI picks the UV method. The pipeline engineer wires
// `field` here (and may make it the default); nothing else in the CLI knows
// which methods exist.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "soupuv/io/asset.h"
#include "soupuv/progress.h"
#include "soupuv/vec.h"

namespace soupuv::cli {

// The method `map` uses when --method is absent.
inline constexpr const char* kDefaultMethod = "box";

struct MethodRun {
  std::vector<Vec2> corner_uvs;  // 3 per soup triangle
  // Diagnostics the method contributes: at least "uv" and "stages" (stage
  // name -> {"seconds": s}); may add "proxy", "atlas", "trace", "cache", ...
  nlohmann::json diagnostics = nlohmann::json::object();
};

// Throws UsageError for an unknown method, Error{not_built} for one that is
// not implemented yet.
MethodRun compute_uvs(const io::Asset& asset, const std::string& method, Progress& progress);

}  // namespace soupuv::cli
