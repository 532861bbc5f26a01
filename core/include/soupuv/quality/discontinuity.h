// Why a field-line map is discontinuous: each originally adjacent pair that
// fails the continuity test, and each flipped triangle, put down to one cause.
//
// Input : the soup, its metric adjacency, final corner UVs, the scale the
//         metric used, and per corner what the transfer saw: the line missed
//         the proxy, the chart it first landed on and the chart it ended on
//         after the §8 correction.
// Output: counts per cause (first matching cause wins, in this order):
//   missed      a shared corner's line missed the proxy (a fallback placed it);
//   split       the two copies of a shared corner landed on different charts;
//   corrected   they landed on one chart, but §8 moved one of them elsewhere;
//   diverged    one chart throughout, yet the landing points lie apart
//               (the lines parted between soup and proxy);
// and, when the landing knows each corner's line, the diverged pairs once
// more by why: the copies started different lines (diverged_apart_lines:
// their seeds were not welded), or not (diverged_one_line: one line, moved
// apart afterwards);
// and flipped triangles as line crossings (all corners on one chart, no
// miss) or chart/miss trouble (the rest); the L2 stretch of both groups.
#pragma once

#include <cstdint>
#include <vector>

#include <nlohmann/json.hpp>

#include "soupuv/quality/uv_metrics.h"
#include "soupuv/geometry/weld.h"
#include "soupuv/soup.h"

namespace soupuv::quality {

struct CornerLanding {
  std::vector<uint8_t> missed;    // per corner (triangle * 3 + k)
  std::vector<int> first_chart;   // before §8
  std::vector<int> final_chart;   // after §8
  // Optional (empty: unknown): the field line each corner's UV came from.
  std::vector<uint32_t> line;
};

struct DiscontinuityBreakdown {
  size_t pairs = 0, discontinuous = 0;
  size_t missed = 0, split = 0, corrected = 0, diverged = 0;
  size_t diverged_apart_lines = 0, diverged_one_line = 0;
  size_t flipped = 0, flipped_one_chart = 0, flipped_other = 0;
  // L2 stretch (uv_metrics' normalisation) of the triangles whose corners all
  // hit one chart, and of the others (chart correction or fallback placed them).
  double stretch_l2_one_chart = 0, stretch_l2_other = 0;
  double stretch_l2_unflipped = 0;  // without the flipped triangles
  size_t one_chart_triangles = 0;
  // The worst 1 % of triangles by their term in the squared L2 stretch sum,
  // by what their corners saw (first match wins): a line missed, corners
  // first landed on different charts, §8 moved a corner, or none of these
  // (one chart throughout: the lines themselves converged); and the share
  // of the squared sum each group carries.
  size_t worst_stretch_triangles = 0;
  size_t worst_stretch_missed = 0, worst_stretch_split = 0, worst_stretch_corrected = 0,
         worst_stretch_one_chart = 0;
  double worst_stretch_share_missed = 0, worst_stretch_share_split = 0,
         worst_stretch_share_corrected = 0, worst_stretch_share_one_chart = 0;
  nlohmann::json to_json() const;
};

DiscontinuityBreakdown discontinuity_breakdown(const Soup& soup, const CornerUvs& uvs,
                                               const std::vector<geometry::AdjacentPair>& adjacency,
                                               const CornerLanding& landing,
                                               int texture_size, double uv_per_length);

}  // namespace soupuv::quality
