// How a benchmark suite plugs into soupuv-bench: a file defines
//   static soupuv::bench::Suite reg("charge", "what it measures", run_charge);
// and run_charge(args) prints JSON Lines (one object per measurement, then one
// object with kind:"summary") on stdout. Human-readable progress goes to stderr.
#pragma once

#include <functional>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace soupuv::bench {

struct Args {
  bool quick = false;                  // --quick: small sizes for CI
  std::vector<std::string> rest;       // suite-specific flags
};

using SuiteFn = std::function<int(const Args&)>;

struct SuiteInfo {
  std::string description;
  SuiteFn run;
};

std::map<std::string, SuiteInfo>& registry();

struct Suite {
  Suite(const std::string& name, const std::string& description, SuiteFn fn) {
    registry()[name] = {description, std::move(fn)};
  }
};

// Prints one JSON Lines row and flushes, so partial results survive a crash.
void emit(const nlohmann::json& row);

// Peak resident set size of this process so far, in MiB (VmHWM).
double peak_rss_mb();

// Threads the benchmark runs with (OpenMP max threads).
int threads();

// Least-squares slope of log(y) against log(x).
double loglog_slope(const std::vector<double>& x, const std::vector<double>& y);

}  // namespace soupuv::bench
