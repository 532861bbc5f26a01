// soupuv-bench SUITE [--quick] [suite flags]: runs one benchmark suite and
// prints JSON Lines on stdout.
#include <omp.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <string>

#include "soupuv/openmp_wait.h"
#include "bench_registry.h"

namespace soupuv::bench {

std::map<std::string, SuiteInfo>& registry() {
  static std::map<std::string, SuiteInfo> suites;
  return suites;
}

void emit(const nlohmann::json& row) {
  std::cout << row.dump() << std::endl;
}

double peak_rss_mb() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line))
    if (line.rfind("VmHWM:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;
  return 0.0;
}

int threads() { return omp_get_max_threads(); }

double loglog_slope(const std::vector<double>& x, const std::vector<double>& y) {
  size_t n = std::min(x.size(), y.size());
  if (n < 2) return NAN;
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (size_t i = 0; i < n; ++i) {
    double lx = std::log(x[i]), ly = std::log(y[i]);
    sx += lx; sy += ly; sxx += lx * lx; sxy += lx * ly;
  }
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

}  // namespace soupuv::bench

int main(int argc, char** argv) {
  soupuv::exec_with_sleeping_openmp_waiters(argv);
  using namespace soupuv::bench;
  auto usage = [] {
    std::cerr << "usage: soupuv-bench SUITE [--quick] [flags]\nsuites:\n";
    for (auto& [name, info] : registry()) std::cerr << "  " << name << "  " << info.description << "\n";
  };
  if (argc < 2) { usage(); return 2; }
  std::string suite = argv[1];
  auto it = registry().find(suite);
  if (it == registry().end()) {
    std::cerr << "soupuv-bench: unknown suite '" << suite << "'\n";
    usage();
    return 2;
  }
  Args args;
  for (int i = 2; i < argc; ++i) {
    std::string a = argv[i];
    if (a == "--quick") args.quick = true;
    else args.rest.push_back(a);
  }
  try {
    return it->second.run(args);
  } catch (const std::exception& e) {
    std::cerr << "soupuv-bench " << suite << ": " << e.what() << "\n";
    return 1;
  }
}
