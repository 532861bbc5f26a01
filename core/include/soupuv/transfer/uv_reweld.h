// Continuity repair after the UV repair: copies of one vertex that ended at
// different UVs on one chart are brought back to a common UV wherever that
// folds nothing (a documented post-process, not the paper's).
//
// Why: the UV repair moves "UV vertices" of its own weld, and its strict
// retry welds more sparsely still (where the soup's rows lie closer than its
// noise, a teapot's rim); copies that shared one field line, and so one UV,
// end up apart, and each such split cuts the texture between triangles that
// were neighbours. Where joining them again is harmless, it should be done.
//
// Input : the soup; `groups` (corner -> group: the copies that should share a
//         UV, e.g. the corners of one shared field line); each triangle's
//         chart; the atlas's texel scale (UV units per 3D length); corner UVs.
// Output: corner UVs where, per (group, chart), the copies' distinct UVs were
//         joined pairwise, closest first, at the best of {their area-weighted
//         mean, either one}: the one whose triangles keep the least symmetric
//         Dirichlet energy (against their own 3D shape at the texel scale),
//         with no triangle folded, collapsed below 1/1000 of its isometric
//         area, or pushed past max_energy_density unless it was already
//         worse. Copies on different charts (a seam) are never joined.
// Cost  : O(corners) expected; a group with k distinct UVs costs O(k^3).
#pragma once

#include <array>
#include <vector>

#include <nlohmann/json.hpp>

#include "soupuv/quality/weld.h"
#include "soupuv/soup.h"

namespace soupuv::transfer {

struct UvReweldOptions {
  // Symmetric Dirichlet energy per rest area (4 for an isometry; 7 for a
  // triangle stretched 2.2x along one direction) a joined triangle may reach
  // when it was better before.
  double max_energy_density = 8;
  int sweeps = 2;  // a join can make room for another
};

struct UvReweldResult {
  size_t split_vertices = 0;     // (group, chart) with more than one UV before
  size_t joined_vertices = 0;    // ... brought to one UV
  size_t joins = 0;              // pairwise joins made
  size_t refused = 0;            // pairs no candidate could join
  size_t moved_corners = 0;
  double seconds = 0;
  nlohmann::json diagnostics() const;
};

UvReweldResult reweld_uvs(const Soup& soup, const quality::Weld& groups,
                          const std::vector<int>& triangle_chart, double uv_per_length,
                          std::vector<std::array<Vec2, 3>>& corner_uvs,
                          const UvReweldOptions& options = {});

}  // namespace soupuv::transfer
