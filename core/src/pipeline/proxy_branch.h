// The proxy branch of run_map (paper Fig. 3): proxy, then its atlas.
//
//   run_proxy_branch(soup, proxy, atlas, relax_gate, threads, progress, b, proxy_done)
//     soup        the triangle soup
//     proxy       ProxyOptions for build_proxy
//     atlas       AtlasOptions for build_atlas (threads are overridden)
//     relax_gate  MapOptions::relax_max_soup_per_proxy_face: the seam
//                 relaxation runs only on soups this coarse (0: always)
//     proxy_done  if set, called with b's proxy mesh as soon as it is built,
//                 before the atlas (the field branch's trace stops at it);
//                 the mesh stays where it is while `b` lives
//   -> b: the proxy, its atlas and each stage's wall seconds.
//
//   build_branch_atlas(soup, proxy_result, atlas, relax_gate, threads, progress)
//     the atlas half alone, for a candidate that reuses a proxy already built.
#pragma once

#include <functional>

#include "soupuv/atlas/build_atlas.h"
#include "soupuv/progress.h"
#include "soupuv/proxy/proxy.h"
#include "soupuv/soup.h"

namespace soupuv::pipeline {

struct ProxyBranch {
  proxy::ProxyResult proxy;
  atlas::AtlasResult atlas;
  double seconds_proxy = 0, seconds_atlas = 0;
};

void run_proxy_branch(const Soup& soup, const proxy::ProxyOptions& proxy, const atlas::AtlasOptions& atlas,
                      double relax_gate, int threads, Progress& progress, ProxyBranch& b,
                      const std::function<void(const TriMesh&)>& proxy_done = {});

// Fills b.atlas and b.seconds_atlas from b.proxy.
void build_branch_atlas(const Soup& soup, ProxyBranch& b, const atlas::AtlasOptions& atlas,
                        double relax_gate, int threads, Progress& progress);

// Soup triangles per proxy face: the coarseness the relaxation and the
// candidate search are gated by.
double soup_per_proxy_face(const Soup& soup, const proxy::ProxyResult& proxy);

}  // namespace soupuv::pipeline
