// soupuv-bench charge: paper Tables 3 and 4. Table 3: convergence (error vs
// iterations vs seconds) of robin hood and Krylov on a sphere, torus,
// cylinder and cube of ~5,000 triangles. Table 4: torus (R=1, r=0.5) from
// 800 up to 105,800 triangles: robin hood with direct and with FMM
// initialisation, Krylov+FMM, and dense LU up to 6,400. Every row's
// max_rel_potential_error is the true, re-evaluated deviation. Flags:
// --max-triangles N (cap Table 4), --rh-seconds S (robin hood time cap),
// --tables 3,4 (which tables), --sizes 800,12800 (Table 4 sizes),
// --methods krylov,robin-hood,robin-hood-direct-init,dense-lu, --threads T
// (Krylov thread count; default 0: one thread below krylov_parallel_min),
// --rh-cap-factor F (robin hood's cap is at least F x the same size's
// Krylov solve time, default 5.5, so a capped robin hood row still proves
// the ">= 5x" ratio as a lower bound), --noisy-torus N (adds a Krylov row
// "torus-noisy" on the pipeline's soup: shapes::to_soup(torus_with(1, 0.5,
// N), 1e-3, 1), as `soupuv-bench pipeline --only torus-100k` charges it).
//
// Ratios: every shape/size where both solvers ran gives a row in the
// summary's `ratios` (robin hood solve seconds / Krylov solve seconds, wall
// and CPU). Robin hood "reached" when its true error is <= max(Krylov's true
// error, tolerance); a row that did not reach it was stopped by its cap, so
// its time and ratio are lower bounds (`ratio_lower_bound: true`).
#include <algorithm>
#include <cstdio>
#include <ctime>
#include <string>

#include "bench_registry.h"
#include "soupuv/field/field.h"
#include "testing/shapes.h"

using namespace soupuv;
using namespace soupuv::field;

namespace {

std::vector<std::string> split(const std::string& list) {
  std::vector<std::string> out;
  size_t start = 0;
  while (start <= list.size()) {
    size_t end = list.find(',', start);
    if (end == std::string::npos) end = list.size();
    if (end > start) out.push_back(list.substr(start, end - start));
    start = end + 1;
  }
  return out;
}

nlohmann::json run(const std::string& table, const std::string& shape, const Soup& soup, ChargeOptions o,
                   bool with_history) {
  const std::clock_t c0 = std::clock();
  ChargeResult r = solve_charges(soup, o);
  const double cpu = static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC;
  nlohmann::json row = {{"suite", "charge"},      {"table", table},
                        {"shape", shape},         {"triangles", soup.triangles.size()},
                        {"method", r.solver},     {"seconds", r.seconds},
                        {"solve_seconds", r.solve_seconds},
                        {"threads", bench::threads()},
                        {"iterations", r.iterations},
                        {"max_rel_potential_error", r.max_rel_potential_error},
                        {"verified_by", r.verified_by},
                        {"tolerance", o.tolerance},
                        {"fmm_order", r.fmm_order},
                        {"fmm_theta", r.fmm_theta},
                        {"converged", r.converged},
                        {"cpu_seconds", cpu},
                        {"solve_cpu_seconds", r.solve_cpu_seconds},
                        {"setup_seconds", r.setup_seconds},
                        {"cheap_matvecs", r.cheap_matvecs},
                        {"full_matvecs", r.full_matvecs},
                        {"near_entries", r.near_entries},
                        {"peak_rss_mb", bench::peak_rss_mb()}};
  if (with_history) {
    nlohmann::json h = nlohmann::json::array();
    for (size_t i = 0; i < r.history.size(); ++i)
      h.push_back({{"iterations", r.history_iterations[i]}, {"seconds", r.history_seconds[i]}, {"estimate", r.history[i]}});
    row["history"] = h;
  }
  bench::emit(row);
  std::fprintf(stderr, "charge %s %s n=%zu %s: %.2fs (solve %.2fs, solve cpu %.2fs, setup %.2fs, cpu %.2fs), %d it (%d cheap, %d full), err %.2e\n",
               table.c_str(), shape.c_str(), soup.triangles.size(), r.solver.c_str(), r.seconds, r.solve_seconds,
               r.solve_cpu_seconds, r.setup_seconds, cpu, r.iterations, r.cheap_matvecs, r.full_matvecs, r.max_rel_potential_error);
  return row;
}

// Robin hood against Krylov on one shape: both rows from the same run.
nlohmann::json ratio_row(const nlohmann::json& krylov, const nlohmann::json& rh, double cap) {
  const double ke = krylov["max_rel_potential_error"], re = rh["max_rel_potential_error"];
  const double tol = krylov["tolerance"];
  const bool reached = re <= std::max(ke, tol);
  return {{"table", krylov["table"]},
          {"shape", krylov["shape"]},
          {"triangles", krylov["triangles"]},
          {"krylov_solve_seconds", krylov["solve_seconds"]},
          {"krylov_solve_cpu_seconds", krylov["solve_cpu_seconds"]},
          {"krylov_error", ke},
          {"robin_hood_solve_seconds", rh["solve_seconds"]},
          {"robin_hood_solve_cpu_seconds", rh["solve_cpu_seconds"]},
          {"robin_hood_error", re},
          {"robin_hood_cap_seconds", cap},
          {"robin_hood_reached", reached},
          {"ratio", rh["solve_seconds"].get<double>() / krylov["solve_seconds"].get<double>()},
          {"cpu_ratio", rh["solve_cpu_seconds"].get<double>() / krylov["solve_cpu_seconds"].get<double>()},
          {"ratio_lower_bound", !reached}};
}

int run_charge(const bench::Args& args) {
  double rh_seconds = args.quick ? 5 : 120;
  double rh_cap_factor = 5.5;
  size_t max_tris = args.quick ? 3200 : 105800;
  std::string tables = "3,4", methods = "krylov,robin-hood,robin-hood-direct-init,dense-lu";
  std::vector<int> sizes = {800, 1800, 3200, 6400, 12800, 25600, 51200, 105800};
  std::vector<int> noisy_sizes;
  ChargeOptions krylov_base;
  for (const std::string& a : args.rest)
    if (a == "--no-coarse") krylov_base.krylov_coarse_correction = false;  // block-Jacobi alone
  for (size_t i = 0; i + 1 < args.rest.size(); ++i) {
    if (args.rest[i] == "--max-triangles") max_tris = std::stoul(args.rest[i + 1]);
    if (args.rest[i] == "--rh-seconds") rh_seconds = std::stod(args.rest[i + 1]);
    if (args.rest[i] == "--rh-cap-factor") rh_cap_factor = std::stod(args.rest[i + 1]);
    if (args.rest[i] == "--tables") tables = args.rest[i + 1];
    // Krylov tuning knobs (defaults: ChargeOptions)
    if (args.rest[i] == "--leaf") krylov_base.krylov_leaf_size = std::stoi(args.rest[i + 1]);
    if (args.rest[i] == "--block") krylov_base.krylov_block_size = std::stoi(args.rest[i + 1]);
    if (args.rest[i] == "--overlap") krylov_base.krylov_overlap_ratio = std::stod(args.rest[i + 1]);
    if (args.rest[i] == "--max-iterations") krylov_base.max_iterations = std::stoi(args.rest[i + 1]);
    if (args.rest[i] == "--inner-order") krylov_base.krylov_inner_order = std::stoi(args.rest[i + 1]);
    if (args.rest[i] == "--inner-tol") krylov_base.krylov_inner_tolerance = std::stod(args.rest[i + 1]);
    if (args.rest[i] == "--order") krylov_base.fmm_order = std::stoi(args.rest[i + 1]);
    if (args.rest[i] == "--theta") krylov_base.fmm_theta = std::stod(args.rest[i + 1]);
    if (args.rest[i] == "--verify-direct-max") krylov_base.verify_direct_max = std::stoul(args.rest[i + 1]);
    if (args.rest[i] == "--methods") methods = args.rest[i + 1];
    if (args.rest[i] == "--threads") krylov_base.threads = std::stoi(args.rest[i + 1]);
    if (args.rest[i] == "--noisy-torus")
      for (const std::string& t : split(args.rest[i + 1])) noisy_sizes.push_back(std::stoi(t));
    if (args.rest[i] == "--sizes") {
      sizes.clear();
      for (const std::string& t : split(args.rest[i + 1])) sizes.push_back(std::stoi(t));
      max_tris = SIZE_MAX;
    }
  }
  auto wanted = [](const std::string& list, const std::string& item) {
    for (const std::string& t : split(list))
      if (t == item) return true;
    return false;
  };
  const double tol = 1e-6;
  // Table 3
  struct Shape {
    std::string name;
    Soup soup;
  };
  std::vector<Shape> shapes3;
  if (!wanted(tables, "3")) {
  } else if (args.quick) {
    shapes3 = {{"sphere", shapes::to_soup(shapes::sphere_with(1.0, 1200))},
               {"cube", shapes::to_soup(shapes::cube(1.0, 10))}};
  } else {
    shapes3 = {{"sphere", shapes::to_soup(shapes::sphere_with(1.0, 4900))},
               {"torus", shapes::to_soup(shapes::torus_with(1.0, 0.5, 5000))},
               {"cylinder", shapes::to_soup(shapes::cylinder(0.5, 2.0, 50, 40, 10))},
               {"cube", shapes::to_soup(shapes::cube(1.0, 20))}};
  }
  double cube_krylov_seconds = 0;
  nlohmann::json ratios = nlohmann::json::array();
  // Robin hood's wall cap for a shape whose Krylov row took `krylov_seconds`.
  auto rh_cap = [&](const nlohmann::json& krylov) {
    return krylov.is_null() ? rh_seconds : std::max(rh_seconds, rh_cap_factor * krylov["solve_seconds"].get<double>());
  };
  for (auto& s : shapes3) {
    ChargeOptions k = krylov_base;
    k.tolerance = tol;
    nlohmann::json krylov_row;
    if (wanted(methods, "krylov")) {
      krylov_row = run("3", s.name, s.soup, k, true);
      if (s.name == "cube") cube_krylov_seconds = krylov_row["solve_seconds"];
    }
    if (!wanted(methods, "robin-hood")) continue;
    ChargeOptions rh;
    rh.solver = ChargeOptions::Solver::robin_hood;
    rh.tolerance = tol;
    rh.max_seconds = rh_cap(krylov_row);
    auto rh_row = run("3", s.name, s.soup, rh, true);
    if (!krylov_row.is_null()) ratios.push_back(ratio_row(krylov_row, rh_row, rh.max_seconds));
  }
  // Table 4. Slopes and ratios use solve_seconds (the solve without the
  // independent verification, which is the benchmark's check, not the work).
  if (!wanted(tables, "4")) sizes.clear();
  struct Series {
    std::vector<double> n, seconds, cpu;
    void add(double tris, const nlohmann::json& row) {
      n.push_back(tris);
      seconds.push_back(row["solve_seconds"]);
      cpu.push_back(row["solve_cpu_seconds"]);
    }
  };
  std::map<std::string, Series> fit;
  nlohmann::json krylov_last, rh_last;
  size_t n_last = 0;
  for (int n : sizes) {
    if (static_cast<size_t>(n) > max_tris) break;
    Soup soup = shapes::to_soup(shapes::torus_with(1.0, 0.5, n));
    n_last = n;
    krylov_last = rh_last = nullptr;
    if (wanted(methods, "krylov")) {
      ChargeOptions k = krylov_base;
      k.tolerance = tol;
      krylov_last = run("4", "torus", soup, k, false);
      fit["krylov"].add(n, krylov_last);
    }
    ChargeOptions rh;
    rh.solver = ChargeOptions::Solver::robin_hood;
    rh.tolerance = tol;
    rh.max_seconds = rh_cap(krylov_last);
    if (wanted(methods, "robin-hood")) {
      rh_last = run("4", "torus", soup, rh, false);
      fit["robin-hood"].add(n, rh_last);
      if (!krylov_last.is_null()) ratios.push_back(ratio_row(krylov_last, rh_last, rh.max_seconds));
    }
    if (n <= 12800 && wanted(methods, "robin-hood-direct-init")) {
      ChargeOptions rd = rh;
      rd.direct_initialization = true;
      fit["robin-hood-direct-init"].add(n, run("4", "torus", soup, rd, false));
    }
    if (n <= 6400 && wanted(methods, "dense-lu")) {
      ChargeOptions d;
      d.solver = ChargeOptions::Solver::dense_lu;
      fit["dense-lu"].add(n, run("4", "torus", soup, d, false));
    }
  }
  // The pipeline's noisy soup (issue 6): every triangle its own three
  // vertices, each moved by up to 1e-3 of the diagonal.
  nlohmann::json noisy = nlohmann::json::array();
  for (int n : noisy_sizes) {
    ChargeOptions k = krylov_base;
    k.tolerance = tol;
    noisy.push_back(run("noisy", "torus-noisy", shapes::to_soup(shapes::torus_with(1.0, 0.5, n), 1e-3, 1), k, true));
  }
  nlohmann::json slopes, cpu_slopes;
  for (auto& [m, xy] : fit) {
    slopes[m] = bench::loglog_slope(xy.n, xy.seconds);
    cpu_slopes[m] = bench::loglog_slope(xy.n, xy.cpu);
  }
  // Krylov over the upper range (12,800 .. largest) as the issue asks.
  Series upper;
  for (size_t i = 0; i < fit["krylov"].n.size(); ++i)
    if (fit["krylov"].n[i] >= 12800) {
      upper.n.push_back(fit["krylov"].n[i]);
      upper.seconds.push_back(fit["krylov"].seconds[i]);
      upper.cpu.push_back(fit["krylov"].cpu[i]);
    }
  // The ratio at the largest torus: robin hood ran with a cap of at
  // least rh_cap_factor x the Krylov time, so if it was stopped by the cap
  // the measured ratio is a lower bound that alone decides the ">= 5x".
  const bool at_largest = !ratios.empty() && ratios.back()["table"] == "4" && ratios.back()["triangles"] == n_last;
  const nlohmann::json largest = at_largest ? ratios.back() : nlohmann::json(nullptr);
  bench::emit({{"suite", "charge"},
               {"kind", "summary"},
               {"threads", bench::threads()},
               {"slope", slopes},
               {"cpu_slope", cpu_slopes},
               {"krylov_slope_from_12800", upper.n.size() >= 2 ? bench::loglog_slope(upper.n, upper.seconds) : NAN},
               {"krylov_cpu_slope_from_12800", upper.n.size() >= 2 ? bench::loglog_slope(upper.n, upper.cpu) : NAN},
               {"largest_torus_triangles", n_last},
               {"krylov_solve_seconds_at_largest", krylov_last.is_null() ? nlohmann::json(nullptr) : krylov_last["solve_seconds"]},
               {"robin_hood_over_krylov_seconds_at_largest", largest.is_null() ? nlohmann::json(nullptr) : largest["ratio"]},
               {"ratio_lower_bound", largest.is_null() ? nlohmann::json(nullptr) : largest["ratio_lower_bound"]},
               {"robin_hood_error_at_largest", largest.is_null() ? nlohmann::json(nullptr) : largest["robin_hood_error"]},
               {"robin_hood_cap_factor", rh_cap_factor},
               {"ratios", ratios},
               {"cube_krylov_seconds", cube_krylov_seconds},
               {"noisy_torus", [&] {
                  nlohmann::json out = nlohmann::json::array();
                  for (const auto& row : noisy)
                    out.push_back({{"triangles", row["triangles"]}, {"seconds", row["seconds"]},
                                   {"solve_seconds", row["solve_seconds"]}, {"cpu_seconds", row["cpu_seconds"]},
                                   {"iterations", row["iterations"]},
                                   {"max_rel_potential_error", row["max_rel_potential_error"]}});
                  return out;
                }()},
               {"note", "slopes and ratios from solve_seconds (verification excluded). Robin hood is capped at "
                        "max(--rh-seconds, rh_cap_factor x the same shape's Krylov solve seconds); a row that did "
                        "not reach max(Krylov error, tolerance) is a lower bound (ratio_lower_bound), and with "
                        "rh_cap_factor >= 5 that bound alone decides the >= 5x target"}});
  return 0;
}

bench::Suite reg("charge", "charge solve: Tables 3 and 4 (robin hood, Krylov+FMM, dense LU)", run_charge);

}  // namespace
