// The checks every proxy must pass, re-measured independently of
// build_proxy's own diagnostics where that is cheap.
#pragma once

#include <gtest/gtest.h>

#include "soupuv/proxy/mesh_checks.h"
#include "soupuv/proxy/proxy.h"
#include "soupuv/geometry/distance_bvh.h"

namespace soupuv::proxy {

inline void expect_valid_proxy(const ProxyResult& r, const Soup& soup, int outer_components) {
  SCOPED_TRACE(r.diagnostics().dump());
  EXPECT_TRUE(r.closed);
  EXPECT_TRUE(r.manifold);
  EXPECT_TRUE(r.outward);
  EXPECT_TRUE(r.encloses);
  EXPECT_TRUE(r.self_intersections_checked);
  EXPECT_FALSE(r.self_intersections);
  EXPECT_GE(r.min_distance_ratio, 0.5);
  EXPECT_EQ(r.outer_components, outer_components);
  EXPECT_EQ(r.proxy.outer_components, outer_components);
  EXPECT_EQ(r.triangles, r.proxy.mesh.faces.size());
  EXPECT_GT(r.triangles, 0u);
  // Independent re-measurement: topology, and a sample of soup vertices inside.
  Topology t = check_topology(r.proxy.mesh);
  EXPECT_TRUE(t.closed && t.oriented && t.manifold);
  EXPECT_EQ(t.degenerate_faces, 0u);
  EXPECT_EQ(t.euler(), r.euler);
  geometry::DistanceBvh bvh(r.proxy.mesh);
  size_t step = std::max<size_t>(1, soup.positions.size() / 200), outside = 0;
  for (size_t i = 0; i < soup.positions.size(); i += step) outside += !bvh.contains(soup.positions[i]);
  EXPECT_EQ(outside, 0u);
}

}  // namespace soupuv::proxy
