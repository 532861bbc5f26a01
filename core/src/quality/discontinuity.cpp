#include "soupuv/quality/discontinuity.h"

#include <algorithm>
#include <cmath>

#include "soupuv/geometry/triangle_stretch.h"

namespace soupuv::quality {

nlohmann::json DiscontinuityBreakdown::to_json() const {
  return {{"pairs", pairs},
          {"discontinuous", discontinuous},
          {"missed", missed},
          {"split_charts", split},
          {"chart_correction", corrected},
          {"diverged", diverged},
          {"diverged_apart_lines", diverged_apart_lines},
          {"diverged_one_line", diverged_one_line},
          {"flipped", flipped},
          {"flipped_one_chart", flipped_one_chart},
          {"flipped_other", flipped_other},
          {"one_chart_triangles", one_chart_triangles},
          {"stretch_l2_one_chart", stretch_l2_one_chart},
          {"stretch_l2_other", stretch_l2_other},
          {"stretch_l2_unflipped", stretch_l2_unflipped},
          {"worst_stretch",
           {{"triangles", worst_stretch_triangles},
            {"missed", worst_stretch_missed},
            {"split_charts", worst_stretch_split},
            {"chart_correction", worst_stretch_corrected},
            {"one_chart", worst_stretch_one_chart},
            {"share_missed", worst_stretch_share_missed},
            {"share_split_charts", worst_stretch_share_split},
            {"share_chart_correction", worst_stretch_share_corrected},
            {"share_one_chart", worst_stretch_share_one_chart}}}};
}

DiscontinuityBreakdown discontinuity_breakdown(const Soup& soup, const CornerUvs& uvs,
                                               const std::vector<geometry::AdjacentPair>& adjacency,
                                               const CornerLanding& landing,
                                               int texture_size, double uv_per_length) {
  DiscontinuityBreakdown b;
  b.pairs = adjacency.size();
  const double texel = 1.0 / texture_size;
  const bool know_lines = landing.line.size() == 3 * uvs.size();
  for (const geometry::AdjacentPair& p : adjacency) {
    bool apart = false, missed = false, split = false, corrected = false,
         two_lines = false;
    for (int i = 0; i < 2; ++i) {
      const size_t ca = 3 * size_t(p.a) + p.a_corner[i], cb = 3 * size_t(p.b) + p.b_corner[i];
      const double d_3d = norm(soup.corner(p.a, p.a_corner[i]) - soup.corner(p.b, p.b_corner[i]));
      // The same test as uv_metrics' noise-aware continuity.
      auto cut = [&](const CornerUvs& u) {
        return !(norm(u[p.a][p.a_corner[i]] - u[p.b][p.b_corner[i]]) <= texel + 2 * d_3d * uv_per_length);
      };
      apart |= cut(uvs);
      missed |= landing.missed[ca] || landing.missed[cb];
      split |= landing.first_chart[ca] != landing.first_chart[cb];
      corrected |= landing.final_chart[ca] != landing.first_chart[ca] ||
                   landing.final_chart[cb] != landing.first_chart[cb];
      if (know_lines) two_lines |= landing.line[ca] != landing.line[cb];
    }
    if (!apart) continue;
    ++b.discontinuous;
    if (missed) ++b.missed;
    else if (split) ++b.split;
    else if (corrected) ++b.corrected;
    else {
      ++b.diverged;
      if (two_lines) ++b.diverged_apart_lines;
      else if (know_lines) ++b.diverged_one_line;
    }
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

  // The worst 1 % of the squared L2 sum, by cause.
  std::vector<std::pair<double, uint32_t>> terms;
  double sum = 0;
  for (size_t t = 0; t < uvs.size(); ++t) {
    const double a = triangle_area(soup, t);
    geometry::SanderStretch st;
    if (!(a > 0) || !geometry::sander_stretch(soup.corner(t, 0), soup.corner(t, 1),
                                             soup.corner(t, 2), uvs[t], st))
      continue;
    terms.push_back({a * 0.5 * (st.big * st.big + st.small * st.small), uint32_t(t)});
    sum += terms.back().first;
  }
  const size_t worst = terms.empty() ? 0 : std::max<size_t>(1, terms.size() / 100);
  std::partial_sort(terms.begin(), terms.begin() + worst, terms.end(),
                    [](const auto& x, const auto& y) { return x.first > y.first; });
  b.worst_stretch_triangles = worst;
  for (size_t i = 0; i < worst; ++i) {
    const size_t t = terms[i].second;
    bool missed = false, split = false, corrected = false;
    for (int k = 0; k < 3; ++k) {
      const size_t c = 3 * t + k;
      missed |= landing.missed[c] != 0;
      split |= landing.first_chart[c] != landing.first_chart[3 * t];
      corrected |= landing.final_chart[c] != landing.first_chart[c];
    }
    const double share = sum > 0 ? terms[i].first / sum : 0;
    if (missed) { ++b.worst_stretch_missed; b.worst_stretch_share_missed += share; }
    else if (split) { ++b.worst_stretch_split; b.worst_stretch_share_split += share; }
    else if (corrected) { ++b.worst_stretch_corrected; b.worst_stretch_share_corrected += share; }
    else { ++b.worst_stretch_one_chart; b.worst_stretch_share_one_chart += share; }
  }
  return b;
}

}  // namespace soupuv::quality
