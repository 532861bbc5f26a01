#include "pipeline/proxy_branch.h"

#include <algorithm>
#include <chrono>

#include "pipeline/seam_weights.h"

namespace soupuv::pipeline {

namespace {
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }
}  // namespace

double soup_per_proxy_face(const Soup& soup, const proxy::ProxyResult& proxy) {
  return double(soup.triangles.size()) / double(std::max<size_t>(1, proxy.proxy.mesh.faces.size()));
}

void build_branch_atlas(const Soup& soup, ProxyBranch& b, const atlas::AtlasOptions& atlas,
                        double relax_gate, int threads, Progress& progress) {
  atlas::AtlasOptions ao = atlas;
  ao.threads = threads;
  auto t1 = Clock::now();
  if (relax_gate > 0 && soup_per_proxy_face(soup, b.proxy) > relax_gate) ao.relax_seams = false;
  // Seams placed by cost: a seam through fine soup cuts more pairs.
  if (ao.relax_seams && ao.soup_seam_weights && ao.seam_weight.empty())
    ao.seam_weight = soup_seam_weights(soup, b.proxy.proxy.mesh, threads);
  b.atlas = atlas::build_atlas(b.proxy.proxy.mesh, ao, progress);
  b.seconds_atlas = since(t1);
}

void run_proxy_branch(const Soup& soup, const proxy::ProxyOptions& proxy, const atlas::AtlasOptions& atlas,
                      double relax_gate, int threads, Progress& progress, ProxyBranch& b,
                      const std::function<void(const TriMesh&)>& proxy_done) {
  proxy::ProxyOptions po = proxy;
  po.threads = threads;
  auto t0 = Clock::now();
  b.proxy = proxy::build_proxy(soup, po, progress);
  b.seconds_proxy = since(t0);
  if (proxy_done) proxy_done(b.proxy.proxy.mesh);
  build_branch_atlas(soup, b, atlas, relax_gate, threads, progress);
}

}  // namespace soupuv::pipeline
