// Job parameters: validation of the API's `params` JSON and its translation
// into `soupuv map` flags. The table in params.cpp is the ONE place that maps
// an API parameter to a CLI flag — adding a parameter is one line there.
#pragma once

#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace soupuv::server {

// Limits on the seam_hints parameter (polylines; points over all polylines).
constexpr size_t kMaxSeamHintLines = 256;
constexpr size_t kMaxSeamHintPoints = 20000;

struct ParamError {
  std::string detail;  // empty: valid
  explicit operator bool() const { return !detail.empty(); }
};

// What the installed CLI accepts, read from `soupuv --help` and `soupuv map --help`.
struct WorkerCapabilities {
  std::set<std::string> flags;  // "--method", "--draco", ...
  bool has_inspect = false;     // `soupuv inspect` exists (used to validate uploads)
  bool has(const std::string& flag) const { return flags.count(flag) != 0; }
};
WorkerCapabilities probe_worker(const std::string& worker_bin);

// Checks types and ranges, fills defaults, and refuses parameters whose flag the
// worker does not know (rather than silently ignoring them). `out` is canonical.
ParamError validate_params(const nlohmann::json& in, const WorkerCapabilities& caps, nlohmann::json& out);

// The flags for one job (everything after `soupuv map IN -o OUT`).
std::vector<std::string> params_to_flags(const nlohmann::json& params, const WorkerCapabilities& caps);

// JSON list of the parameters for the upload page and the OpenAPI test:
// [{name, type, default, min, max, values, flag, supported}].
nlohmann::json describe_params(const WorkerCapabilities& caps);

}  // namespace soupuv::server
