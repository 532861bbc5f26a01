#include "soupuv/server/params.h"

#include <atomic>
#include <cmath>
#include <cstdio>
#include <unistd.h>

#include "soupuv/server/worker_process.h"

namespace soupuv::server {
namespace {

enum class Kind { boolean, integer, number, choice, polylines };

struct ParamSpec {
  const char* name;   // API name in params JSON
  const char* flag;   // soupuv map flag
  Kind kind;
  nlohmann::json fallback;  // default; null: not passed unless given
  double lo = 0, hi = 0;    // integer/number range
  std::vector<std::string> values = {};  // choice
  bool power_of_two = false;             // integer
};

// THE mapping. Keep in sync with `soupuv map --help` (flags not listed there are
// refused with a clear reason until the CLI gains them).
const std::vector<ParamSpec>& specs() {
  static const std::vector<ParamSpec> table = {
      // field is the product's method (the CLI default too); box is the baseline.
      {"method", "--method", Kind::choice, "field", 0, 0, {"box", "field"}},
      {"offset", "--offset", Kind::number, nullptr, 0, 1},
      {"resolution", "--resolution", Kind::integer, nullptr, 8, 4096},
      {"solver", "--solver", Kind::choice, nullptr, 0, 0, {"robin-hood", "krylov"}},
      {"tolerance", "--tolerance", Kind::number, nullptr, 1e-12, 1},
      {"charge_iterations", "--charge-iterations", Kind::integer, nullptr, 1, 100000},
      {"steps", "--steps", Kind::integer, nullptr, 1, 100000},
      {"integrator", "--integrator", Kind::choice, nullptr, 0, 0, {"euler", "midpoint"}},
      {"texture_size", "--texture-size", Kind::integer, nullptr, 64, 4096, {}, true},
      {"padding", "--padding", Kind::integer, nullptr, 0, 256},
      {"draco", "--draco", Kind::boolean, false},
      // The input's base colour re-baked onto the new map; unset: the CLI's
      // default (on when the input has a base-colour texture or vertex colours).
      {"rebake", "--rebake", Kind::boolean, nullptr},
      // Special: the scheduler passes --debug-prefix inside the job's work directory.
      {"debug_outputs", "--debug-prefix", Kind::boolean, false},
      // Special: the scheduler writes the polylines to a file in the job's work
      // directory and passes --seam-hints FILE. Limits: kMaxSeamHint* (params.h).
      {"seam_hints", "--seam-hints", Kind::polylines, nullptr, 0, 0},
  };
  return table;
}

std::string type_name(Kind k) {
  switch (k) {
    case Kind::boolean: return "boolean";
    case Kind::integer: return "integer";
    case Kind::number: return "number";
    case Kind::choice: return "string";
    case Kind::polylines: return "array";
  }
  return "string";
}

// Seam hints: [[[x,y,z], ...], ...]. Bounded so a request cannot make the
// stored params (and the worker's hint file) arbitrarily large; the numbers
// must be finite (a JSON parser may turn 1e999 into infinity).
ParamError check_polylines(const std::string& name, const nlohmann::json& v) {
  const std::string shape = name + " must be an array of polylines, each an array of 2 or more [x, y, z] points";
  if (!v.is_array()) return {shape};
  if (v.size() > kMaxSeamHintLines) return {name + " has more than " + std::to_string(kMaxSeamHintLines) + " polylines"};
  size_t points = 0;
  for (const auto& line : v) {
    if (!line.is_array() || line.size() < 2) return {shape};
    points += line.size();
    if (points > kMaxSeamHintPoints)
      return {name + " has more than " + std::to_string(kMaxSeamHintPoints) + " points in all"};
    for (const auto& p : line) {
      if (!p.is_array() || p.size() != 3) return {shape};
      for (const auto& x : p)
        if (!x.is_number() || !std::isfinite(x.get<double>())) return {name + " coordinates must be finite numbers"};
    }
  }
  return {};
}

}  // namespace

WorkerCapabilities probe_worker(const std::string& worker_bin) {
  // `soupuv capabilities --json`: the worker's commands and map flags, read
  // from its stdout through a pipe, never a temp file (a read-only root file
  // system has no /tmp, and a silent probe failure would leave every job
  // without its flags: /readyz fails when nothing is known).
  WorkerCapabilities caps;
  std::atomic<bool> never{false};
  ProcessLimits limits;
  limits.wall_seconds = 10;
  std::string text;
  auto outcome = run_process({worker_bin, "capabilities", "--json"}, {"PATH=/usr/bin:/bin", "LANG=C.UTF-8"},
                             limits, never, [&](const std::string& line) { text += line + "\n"; });
  text += outcome.stdout_text;
  const nlohmann::json j = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (!j.is_object()) return caps;
  if (j.contains("commands") && j["commands"].is_array())
    for (const auto& c : j["commands"])
      if (c.is_string() && c.get<std::string>() == "inspect") caps.has_inspect = true;
  if (j.contains("map_flags") && j["map_flags"].is_array())
    for (const auto& f : j["map_flags"])
      if (f.is_string()) caps.flags.insert(f.get<std::string>());
  return caps;
}

ParamError validate_params(const nlohmann::json& in, const WorkerCapabilities& caps, nlohmann::json& out) {
  out = nlohmann::json::object();
  if (!in.is_null() && !in.is_object()) return {"params must be a JSON object"};
  if (in.is_object())
    for (auto it = in.begin(); it != in.end(); ++it) {
      bool known = false;
      for (const auto& s : specs()) known = known || it.key() == s.name;
      if (!known) return {"unknown parameter '" + it.key() + "'"};
    }
  for (const auto& s : specs()) {
    bool given = in.is_object() && in.contains(s.name) && !in.at(s.name).is_null();
    nlohmann::json v = given ? in.at(s.name) : s.fallback;
    if (v.is_null()) continue;
    const std::string name = s.name;
    switch (s.kind) {
      case Kind::boolean:
        if (!v.is_boolean()) return {name + " must be a boolean"};
        break;
      case Kind::integer:
        if (!v.is_number_integer() || v.get<double>() < s.lo || v.get<double>() > s.hi)
          return {name + " must be an integer in [" + std::to_string(int64_t(s.lo)) + ", " +
                  std::to_string(int64_t(s.hi)) + "]"};
        if (s.power_of_two && (v.get<int64_t>() & (v.get<int64_t>() - 1)) != 0)
          return {name + " must be a power of two"};
        break;
      case Kind::number:
        if (!v.is_number() || !std::isfinite(v.get<double>()) || v.get<double>() < s.lo ||
            v.get<double>() > s.hi)
          return {name + " must be a number in [" + nlohmann::json(s.lo).dump() + ", " +
                  nlohmann::json(s.hi).dump() + "]"};
        break;
      case Kind::polylines:
        if (auto e = check_polylines(name, v)) return e;
        break;
      case Kind::choice: {
        bool ok = v.is_string();
        bool listed = false;
        for (const auto& c : s.values) listed = listed || (ok && v.get<std::string>() == c);
        if (!listed) {
          std::string all;
          for (const auto& c : s.values) all += (all.empty() ? "" : ", ") + c;
          return {name + " must be one of: " + all};
        }
        break;
      }
    }
    // A default-valued boolean that is false needs no flag; anything else does.
    bool needs_flag = !(s.kind == Kind::boolean && !v.get<bool>()) && (given || !s.fallback.is_null());
    if (needs_flag && !caps.has(s.flag) && given)
      return {"parameter '" + name + "' is not supported by this soupuv build (its CLI has no " +
              s.flag + ")"};
    out[s.name] = v;
  }
  return {};
}

std::vector<std::string> params_to_flags(const nlohmann::json& params, const WorkerCapabilities& caps) {
  std::vector<std::string> flags;
  for (const auto& s : specs()) {
    if (!params.contains(s.name) || !caps.has(s.flag)) continue;
    const auto& v = params.at(s.name);
    if (s.kind == Kind::boolean) {
      if (std::string(s.name) == "rebake") flags.push_back(v.get<bool>() ? "--rebake" : "--no-rebake");
      else if (v.get<bool>() && std::string(s.name) != "debug_outputs") flags.push_back(s.flag);
      continue;
    }
    if (s.kind == Kind::polylines) continue;  // a file, written by the scheduler
    flags.push_back(s.flag);
    flags.push_back(v.is_string() ? v.get<std::string>() : v.dump());
  }
  return flags;
}

nlohmann::json describe_params(const WorkerCapabilities& caps) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& s : specs()) {
    nlohmann::json d = {{"name", s.name}, {"type", type_name(s.kind)}, {"default", s.fallback},
                        {"flag", s.flag}, {"supported", caps.has(s.flag)}};
    if (s.kind == Kind::integer || s.kind == Kind::number) {
      d["min"] = s.lo;
      d["max"] = s.hi;
      if (s.power_of_two) d["power_of_two"] = true;
    }
    if (s.kind == Kind::choice) d["values"] = s.values;
    if (s.kind == Kind::polylines) {
      d["max_polylines"] = kMaxSeamHintLines;
      d["max_points"] = kMaxSeamHintPoints;
    }
    out.push_back(d);
  }
  return out;
}

}  // namespace soupuv::server
