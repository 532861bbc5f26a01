#include "soupuv/quality/discontinuity.h"

#include <cmath>

namespace soupuv::quality {

nlohmann::json DiscontinuityBreakdown::to_json() const {
  return {{"pairs", pairs},
          {"discontinuous", discontinuous},
          {"missed", missed},
          {"split_charts", split},
          {"chart_correction", corrected},
          {"diverged", diverged},
          {"flipped", flipped},
          {"flipped_one_chart", flipped_one_chart},
          {"flipped_other", flipped_other},
          {"one_chart_triangles", one_chart_triangles},
          {"stretch_l2_one_chart", stretch_l2_one_chart},
          {"stretch_l2_other", stretch_l2_other},
          {"stretch_l2_unflipped", stretch_l2_unflipped}};
}

DiscontinuityBreakdown discontinuity_breakdown(const Soup& soup, const CornerUvs& uvs,
                                               const std::vector<AdjacentPair>& adjacency,
                                               const CornerLanding& landing,
                                               int texture_size, double uv_per_length) {
  DiscontinuityBreakdown b;
  b.pairs = adjacency.size();
  const double texel = 1.0 / texture_size;
  for (const AdjacentPair& p : adjacency) {
    bool apart = false, missed = false, split = false, corrected = false;
    for (int i = 0; i < 2; ++i) {
      const size_t ca = 3 * size_t(p.a) + p.a_corner[i], cb = 3 * size_t(p.b) + p.b_corner[i];
      const double d_uv = norm(uvs[p.a][p.a_corner[i]] - uvs[p.b][p.b_corner[i]]);
      const double d_3d = norm(soup.corner(p.a, p.a_corner[i]) - soup.corner(p.b, p.b_corner[i]));
      // The same test as uv_metrics' noise-aware continuity.
      if (!(d_uv <= texel + 2 * d_3d * uv_per_length)) apart = true;
      missed |= landing.missed[ca] || landing.missed[cb];
      split |= landing.first_chart[ca] != landing.first_chart[cb];
      corrected |= landing.final_chart[ca] != landing.first_chart[ca] ||
                   landing.final_chart[cb] != landing.first_chart[cb];
    }
    if (!apart) continue;
    ++b.discontinuous;
    if (missed) ++b.missed;
    else if (split) ++b.split;
    else if (corrected) ++b.corrected;
    else ++b.diverged;
  }
  // Flips against the dominant orientation, as uv_metrics counts them.
  double oriented = 0;
  std::vector<double> area(uvs.size());
  for (size_t t = 0; t < uvs.size(); ++t) {
    area[t] = 0.5 * cross(uvs[t][1] - uvs[t][0], uvs[t][2] - uvs[t][0]);
    if (std::isfinite(area[t])) oriented += area[t];
  }
  const double sign = oriented >= 0 ? 1 : -1;
  std::vector<uint8_t> one_chart(uvs.size(), 1), other(uvs.size(), 0), unflipped(uvs.size(), 1);
  double area3 = 0, area_uv = 0;
  for (size_t t = 0; t < uvs.size(); ++t) {
    area3 += triangle_area(soup, t);
    if (std::isfinite(area[t])) area_uv += std::abs(area[t]);
    for (int k = 0; k < 3; ++k)
      one_chart[t] &= !landing.missed[3 * t + k] &&
                      landing.first_chart[3 * t + k] == landing.first_chart[3 * t];
    other[t] = !one_chart[t];
    b.one_chart_triangles += one_chart[t];
    if (!(sign * area[t] < 0)) continue;
    unflipped[t] = 0;
    ++b.flipped;
    (one_chart[t] ? b.flipped_one_chart : b.flipped_other)++;
  }
  const double scale = area3 > 0 ? std::sqrt(area_uv / area3) : 0;
  b.stretch_l2_one_chart = stretch_l2_subset(soup, uvs, one_chart, scale);
  b.stretch_l2_other = stretch_l2_subset(soup, uvs, other, scale);
  b.stretch_l2_unflipped = stretch_l2_subset(soup, uvs, unflipped, scale);
  return b;
}

}  // namespace soupuv::quality
