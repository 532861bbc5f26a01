// soupuv-bench fmm: FMM error against direct summation for expansion orders
// p = 2 ... 10 (theta 0.5), and FMM time (build + one pass + evaluation at
// the centroids) against n on tori, with its fitted slope.
#include <cstdio>
#include <random>

#include "bench_registry.h"
#include "soupuv/field/direct.h"
#include "soupuv/field/fmm.h"
#include "testing/shapes.h"

using namespace soupuv;
using namespace soupuv::field;

namespace {

int run_fmm(const bench::Args& args) {
  using Clock = std::chrono::steady_clock;
  const int n_err = args.quick ? 3200 : 12800;
  Soup soup = shapes::to_soup(shapes::torus_with(1.0, 0.5, n_err));
  SourceGeometry src = make_sources(soup.positions, soup.triangles, 4);
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(0.5, 1.5);
  std::vector<double> q(src.size());
  for (size_t j = 0; j < q.size(); ++j) q[j] = u(rng) * src.area[j];
  std::vector<Vec3> xs;
  for (size_t j = 0; j < src.size(); j += std::max<size_t>(1, src.size() / 1000)) xs.push_back(src.centroid[j]);
  std::vector<double> phi_d;
  std::vector<Vec3> E_d;
  auto t0 = Clock::now();
  direct_sum(src, q, xs, &phi_d, &E_d);
  double direct_s = std::chrono::duration<double>(Clock::now() - t0).count();
  std::vector<int> orders = args.quick ? std::vector<int>{2, 4, 6, 8} : std::vector<int>{2, 4, 6, 8, 10};
  for (int p : orders) {
    FmmOptions o;
    o.order = p;
    o.theta = 0.5;
    t0 = Clock::now();
    Fmm fmm(src, o, xs);
    fmm.set_charges(q);
    double ep = 0, ee = 0, sp = 0, se = 0;
    for (size_t i = 0; i < xs.size(); ++i) {
      double phi = 0;
      Vec3 E{0, 0, 0};
      fmm.evaluate(xs[i], &phi, &E);
      ep = std::max(ep, std::fabs(phi - phi_d[i]));
      ee = std::max(ee, norm(E - E_d[i]));
      sp = std::max(sp, std::fabs(phi_d[i]));
      se = std::max(se, norm(E_d[i]));
    }
    double s = std::chrono::duration<double>(Clock::now() - t0).count();
    bench::emit({{"suite", "fmm"}, {"shape", "torus"}, {"triangles", n_err}, {"method", "fmm"}, {"order", p},
                 {"theta", 0.5}, {"seconds", s}, {"threads", bench::threads()},
                 {"max_rel_potential_error", ep / sp}, {"max_rel_field_error", ee / se},
                 {"direct_seconds_for_same_targets", direct_s}, {"targets", xs.size()}});
    std::fprintf(stderr, "fmm p=%d: potential %.1e field %.1e\n", p, ep / sp, ee / se);
  }
  std::vector<double> nx, ty;
  std::vector<int> sizes = args.quick ? std::vector<int>{1800, 3200, 6400} : std::vector<int>{3200, 12800, 51200, 105800};
  for (int n : sizes) {
    Soup s2 = shapes::to_soup(shapes::torus_with(1.0, 0.5, n));
    SourceGeometry g = make_sources(s2.positions, s2.triangles, 4);
    std::vector<double> qq(g.size(), 1.0);
    FmmOptions o;
    o.order = 6;
    t0 = Clock::now();
    Fmm fmm(g, o, g.centroid);
    fmm.set_charges(qq);
    double acc = 0;
    for (size_t i = 0; i < g.size(); ++i) {
      double phi = 0;
      fmm.evaluate(g.centroid[i], &phi, nullptr);
      acc += phi;
    }
    double s = std::chrono::duration<double>(Clock::now() - t0).count();
    const FmmStats& st = fmm.stats();
    bench::emit({{"suite", "fmm"}, {"shape", "torus"}, {"triangles", n}, {"method", "fmm-pass"}, {"order", 6},
                 {"theta", 0.5}, {"seconds", s}, {"threads", bench::threads()}, {"m2l_pairs", st.m2l_pairs},
                 {"target_cells", st.target_cells}, {"m2l_seconds", st.m2l_seconds},
                 {"checksum", acc}, {"peak_rss_mb", bench::peak_rss_mb()}});
    nx.push_back(n);
    ty.push_back(s);
  }
  bench::emit({{"suite", "fmm"}, {"kind", "summary"}, {"threads", bench::threads()},
               {"slope", {{"fmm-pass", bench::loglog_slope(nx, ty)}}}});
  return 0;
}

bench::Suite reg("fmm", "FMM error vs order and time vs n", run_fmm);

}  // namespace
