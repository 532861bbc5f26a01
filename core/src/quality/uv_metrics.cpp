#include "soupuv/quality/uv_metrics.h"
#include "soupuv/quality/uv_overlap.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "soupuv/errors.h"
#include "soupuv/union_find.h"
#include "soupuv/geometry/triangle_stretch.h"

namespace soupuv::quality {

namespace {

double signed_uv_area(const std::array<Vec2, 3>& t) {
  return 0.5 * cross(t[1] - t[0], t[2] - t[0]);
}

bool usable(Vec2 p) {
  return std::isfinite(p.x) && std::isfinite(p.y) && p.x >= 0 && p.x <= 1 && p.y >= 0 && p.y <= 1;
}

}  // namespace

UvMetrics uv_metrics(const Soup& soup, const CornerUvs& uvs,
                     const std::vector<geometry::AdjacentPair>& adjacency, const UvMetricsOptions& options) {
  if (uvs.size() != soup.triangles.size())
    throw Error(ErrorCode::internal, "uv_metrics: one UV triple per triangle expected");
  UvMetrics m;
  const size_t n = soup.triangles.size();
  m.triangles = n;
  if (n == 0) return m;

  size_t covered = 0;
  double area3 = 0, area_uv = 0, oriented = 0;
  std::vector<double> a3(n), auv(n);
  for (size_t t = 0; t < n; ++t) {
    for (int k = 0; k < 3; ++k) covered += usable(uvs[t][k]);
    a3[t] = triangle_area(soup, t);
    auv[t] = signed_uv_area(uvs[t]);
    if (!std::isfinite(auv[t])) auv[t] = 0;
    area3 += a3[t];
    area_uv += std::abs(auv[t]);
    oriented += auv[t];
  }
  m.coverage = double(covered) / double(3 * n);

  // Flipped: against the dominant (area-weighted) UV orientation, which is
  // the one a continuous map gives the input's winding; or collapsed to
  // (almost) nothing while the 3D triangle is not.
  const double sign = oriented >= 0 ? 1.0 : -1.0;
  const double mean_ratio = area3 > 0 ? area_uv / area3 : 0;
  for (size_t t = 0; t < n; ++t) {
    bool collapsed = std::abs(auv[t]) <= 1e-6 * mean_ratio * a3[t];
    if (a3[t] > 0 && (sign * auv[t] < 0 || collapsed)) ++m.flipped;
  }
  m.flipped_fraction = double(m.flipped) / double(n);

  m.uv_per_length = options.uv_per_length > 0 ? options.uv_per_length
                                              : (area3 > 0 ? std::sqrt(area_uv / area3) : 0);
  // L2 stretch, normalised by the global scale (Sander et al.: multiply by
  // sqrt(sum A_uv / sum A_3d)) so that any uniformly scaled isometry gives 1.
  // The map is differentiated from UV onto the surface, so a UV triangle
  // squeezed towards a segment (converging field lines) costs ~1/width^2:
  // the figure is dominated by a few such slivers, which the distribution
  // fields below make visible without changing what is measured.
  double sum_l2 = 0, weight = 0, linf = 0;
  const double scale = area3 > 0 ? std::sqrt(area_uv / area3) : 0;
  struct Term { double stretch, area, l2_term; };
  std::vector<Term> terms;
  terms.reserve(n);
  for (size_t t = 0; t < n; ++t) {
    if (!(a3[t] > 0)) continue;
    geometry::SanderStretch st;
    if (!geometry::sander_stretch(soup.corner(t, 0), soup.corner(t, 1), soup.corner(t, 2), uvs[t], st))
      continue;  // collapsed: already counted as flipped
    const double l2_sq = 0.5 * (st.big * st.big + st.small * st.small);
    sum_l2 += a3[t] * l2_sq;
    weight += a3[t];
    linf = std::max(linf, st.big * scale);
    terms.push_back({std::sqrt(l2_sq) * scale, a3[t], a3[t] * l2_sq});
  }
  m.stretch_l2 = weight > 0 ? std::sqrt(sum_l2 / weight) * scale : 0;
  m.stretch_linf = linf;
  if (weight > 0) {
    // Area-weighted median of the per-triangle stretch.
    std::sort(terms.begin(), terms.end(),
              [](const Term& x, const Term& y) { return x.stretch < y.stretch; });
    double below = 0;
    for (const Term& x : terms) {
      below += x.area;
      if (below >= 0.5 * weight) { m.stretch_median = x.stretch; break; }
    }
    // Share of the squared L2 sum carried by the worst 1 % of triangles.
    std::sort(terms.begin(), terms.end(),
              [](const Term& x, const Term& y) { return x.l2_term > y.l2_term; });
    const size_t worst = std::max<size_t>(1, terms.size() / 100);
    double top = 0;
    for (size_t i = 0; i < worst; ++i) top += terms[i].l2_term;
    m.stretch_l2_worst1pct_share = sum_l2 > 0 ? top / sum_l2 : 0;
  }

  // Continuity over originally adjacent pairs, and islands of triangles
  // joined by continuous edges.
  const double texel = 1.0 / options.texture_size;
  UnionFind uf(n);
  size_t ok = 0, ok_plain = 0;
  for (const geometry::AdjacentPair& p : adjacency) {
    bool cont = true, plain = true;
    for (int i = 0; i < 2; ++i) {
      Vec2 ua = uvs[p.a][p.a_corner[i]], ub = uvs[p.b][p.b_corner[i]];
      double d_uv = norm(ua - ub);
      double d_3d = norm(soup.corner(p.a, p.a_corner[i]) - soup.corner(p.b, p.b_corner[i]));
      if (!(d_uv <= texel + 2 * d_3d * m.uv_per_length)) cont = false;
      if (!(d_uv <= texel)) plain = false;
    }
    ok += cont;
    ok_plain += plain;
    if (cont) uf.unite(p.a, p.b);
  }
  m.adjacent_pairs = adjacency.size();
  m.continuity = adjacency.empty() ? 1.0 : double(ok) / double(adjacency.size());
  m.continuity_1texel = adjacency.empty() ? 1.0 : double(ok_plain) / double(adjacency.size());
  for (size_t t = 0; t < n; ++t) m.islands += uf.find(uint32_t(t)) == t;

  std::vector<uint8_t> counted(n, 0);
  for (size_t t = 0; t < n; ++t) {
    bool inside = a3[t] > 0;
    for (int k = 0; k < 3 && inside; ++k) {
      const Vec2 p = uvs[t][k];
      inside = p.x >= -1e-6 && p.x <= 1 + 1e-6 && p.y >= -1e-6 && p.y <= 1 + 1e-6;
    }
    counted[t] = inside;
  }
  const UvOverlap o = uv_overlap(uvs, counted);
  m.utilisation = o.utilisation;
  m.overlap = o.overlap;
  return m;
}

double stretch_l2_subset(const Soup& soup, const CornerUvs& uvs,
                         const std::vector<uint8_t>& include, double scale) {
  double sum = 0, weight = 0;
  for (size_t t = 0; t < uvs.size(); ++t) {
    const double a = triangle_area(soup, t);
    geometry::SanderStretch st;
    if (!include[t] || !(a > 0) ||
        !geometry::sander_stretch(soup.corner(t, 0), soup.corner(t, 1), soup.corner(t, 2), uvs[t], st))
      continue;
    sum += a * 0.5 * (st.big * st.big + st.small * st.small);
    weight += a;
  }
  return weight > 0 ? std::sqrt(sum / weight) * scale : 0;
}

std::vector<geometry::AdjacentPair> metric_adjacency(const Soup& soup, const Soup* original,
                                           double weld_tolerance) {
  if (original) {
    if (original->triangles.size() != soup.triangles.size())
      throw Error(ErrorCode::invalid_input,
                  "the original mesh for continuity has a different triangle count");
    return geometry::edge_adjacency(geometry::weld_corners(*original, 0.0), original->triangles.size());
  }
  return geometry::edge_adjacency(geometry::weld_corners(soup, weld_tolerance), soup.triangles.size());
}

nlohmann::json to_json(const UvMetrics& m) {
  nlohmann::json j = {{"coverage", m.coverage},
          {"flipped", m.flipped},
          {"flipped_fraction", m.flipped_fraction},
          {"stretch_l2", m.stretch_l2},
          {"stretch_linf", m.stretch_linf},
          {"stretch_median", m.stretch_median},
          {"stretch_l2_worst1pct_share", m.stretch_l2_worst1pct_share},
          {"adjacent_pairs", m.adjacent_pairs},
          {"continuity", m.continuity},
          {"continuity_1texel", m.continuity_1texel},
          {"islands", m.islands},
          {"uv_per_length", m.uv_per_length},
          {"utilisation", m.utilisation},
          {"overlap", m.overlap}};
  // Without adjacent pairs continuity would read 1.0 by vacuity: leave it out.
  if (m.adjacent_pairs == 0) {
    j.erase("continuity");
    j.erase("continuity_1texel");
  }
  return j;
}

}  // namespace soupuv::quality
