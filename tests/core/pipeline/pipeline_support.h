// Helpers for the end-to-end tests: test soups with their welded originals
// (same triangle order), one cache shared by the whole suite (so a soup's
// charges and field lines are computed once), and the targets.
#pragma once

#include <gtest/gtest.h>

#include "soupuv/cache/store.h"
#include "soupuv/pipeline.h"
#include "testing/shapes.h"

namespace soupuv::testing {

// A welded mesh as a Soup (shared indices): the continuity reference.
inline Soup welded(const TriMesh& m) {
  Soup s;
  s.positions = m.vertices;
  for (auto f : m.faces) s.triangles.push_back({uint32_t(f[0]), uint32_t(f[1]), uint32_t(f[2])});
  s.origins.resize(s.triangles.size());
  return s;
}

// The paper's Fig. 21: two plates forming a V along a common edge (the y axis).
inline TriMesh v_plates(int n, double half_angle_deg) {
  TriMesh m;
  double a = half_angle_deg * M_PI / 180;
  Vec3 dirs[2] = {{std::sin(a), 0, std::cos(a)}, {-std::sin(a), 0, std::cos(a)}};
  // Vertex (i, j) of plate p: j along y, i along the plate; i = 0 is shared.
  auto id = [&](int p, int i, int j) { return i == 0 ? j : (n + 1) + p * n * (n + 1) + (i - 1) * (n + 1) + j; };
  for (int j = 0; j <= n; ++j) m.vertices.push_back({0, double(j) / n, 0});
  for (int p = 0; p < 2; ++p)
    for (int i = 1; i <= n; ++i)
      for (int j = 0; j <= n; ++j) m.vertices.push_back(dirs[p] * (double(i) / n) + Vec3{0, double(j) / n, 0});
  for (int p = 0; p < 2; ++p)
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        int v00 = id(p, i, j), v10 = id(p, i + 1, j), v11 = id(p, i + 1, j + 1), v01 = id(p, i, j + 1);
        if (p == 0) { m.faces.push_back({v00, v10, v11}); m.faces.push_back({v00, v11, v01}); }
        else { m.faces.push_back({v00, v11, v10}); m.faces.push_back({v00, v01, v11}); }
      }
  return m;
}

// The targets. Continuity is bounded by the atlas's seams: on the
// small soups a ctest can afford (hundreds of triangles) every chart border
// cuts a large share of the pairs, so the 95 % target is checked in
// `soupuv-bench pipeline` on the shared soups and only a floor here
// (measured on the 800-triangle noisy sphere: 0.92 with shared lines and the
// neighbour-aware §8 choice; 0.85 before them).
struct Targets {
  double coverage = 1.0;
  double flipped = 0.005;
  double stretch = 1.3;
  double continuity = 0.9;
};

inline void expect_targets(const nlohmann::json& d, const Targets& t = {}) {
  const auto& uv = d["uv"];
  EXPECT_GE(uv["coverage"].get<double>(), t.coverage) << uv.dump(1);
  EXPECT_LE(uv["flipped_fraction"].get<double>(), t.flipped) << uv.dump(1);
  EXPECT_LE(uv["stretch_l2"].get<double>(), t.stretch) << uv.dump(1);
  EXPECT_GE(uv["continuity"].get<double>(), t.continuity) << uv.dump(1);
}

inline cache::Store& suite_cache() {
  static cache::Store store;
  return store;
}

// Defaults, except a fixed proxy offset (the automatic offset tries a ladder
// of proxies, which the suite cannot afford for every case) and the suite's
// shared cache.
inline MapOptions fast_options() {
  MapOptions o;
  o.threads = 2;
  o.proxy.offset_mode = proxy::OffsetMode::relative;
  o.proxy.offset = 0.03;
  o.cache = &suite_cache();
  return o;
}

}  // namespace soupuv::testing
