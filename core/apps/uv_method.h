// The one place where the CLI picks the UV method and turns the method's flags
// into core options. Both methods go through soupuv::run_map (core/include/
// soupuv/pipeline.h), so they report the same diagnostics.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "soupuv/io/asset.h"
#include "soupuv/pipeline.h"
#include "soupuv/progress.h"
#include "soupuv/vec.h"

namespace soupuv::cli {

// The method `map` uses when --method is absent.
inline constexpr const char* kDefaultMethod = "field";

// Flags of the UV methods (rows of the flag table, map_flags.cpp).
struct MethodFlags {
  MapOptions options;
  std::string cache_dir;     // on-disk cache shared between runs and processes
  std::string debug_prefix;  // PREFIX.proxy.glb, PREFIX.lines.glb, PREFIX.uv.png
  std::string uv_layout;     // PNG of the UV layout alone (the server's /uv-layout.png)
  std::string original;      // continuity reference: welded mesh, same triangle order
  std::string seam_hints;    // JSON file: [[[x,y,z], ...], ...]
};

struct MethodRun {
  std::vector<Vec2> corner_uvs;  // 3 per soup triangle
  // Diagnostics the method contributes: "uv", "stages" (stage name ->
  // {"seconds": s}), and for field "proxy", "atlas", "trace", "cache", ...
  nlohmann::json diagnostics = nlohmann::json::object();
};

// Throws UsageError for an unknown method.
MethodRun compute_uvs(const io::Asset& asset, const std::string& method, const MethodFlags& flags,
                      Progress& progress);

}  // namespace soupuv::cli
