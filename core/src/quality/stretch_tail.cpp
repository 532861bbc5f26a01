#include "soupuv/quality/stretch_tail.h"

#include <algorithm>
#include <cmath>

#include "soupuv/geometry/triangle_stretch.h"

namespace soupuv::quality {

namespace {

const std::vector<std::string> kClasses = {"sliver_3d", "missed", "split", "corrected",
                                           "chart_border", "converged"};

bool flag(const std::vector<uint8_t>& v, size_t t) { return t < v.size() && v[t] != 0; }

}  // namespace

double triangle_aspect(Vec3 a, Vec3 b, Vec3 c) {
  const double longest = std::max({norm(b - a), norm(c - b), norm(a - c)});
  if (!(longest > 0)) return 0;
  const double twice_area = norm(cross(b - a, c - a));
  return twice_area / (longest * longest);  // altitude on the longest edge / that edge
}

StretchTail stretch_tail(const Soup& soup, const CornerUvs& uvs, const CornerLanding& landing,
                         const TailFlags& flags, const StretchTailOptions& options) {
  StretchTail tail;
  tail.classes = kClasses;
  tail.class_count.assign(kClasses.size(), 0);
  tail.class_share.assign(kClasses.size(), 0);
  const size_t n = uvs.size();

  // The same normalisation and terms as uv_metrics' stretch_l2.
  double area3 = 0, area_uv = 0, oriented = 0;
  for (size_t t = 0; t < n; ++t) {
    area3 += triangle_area(soup, t);
    const double a = 0.5 * cross(uvs[t][1] - uvs[t][0], uvs[t][2] - uvs[t][0]);
    if (std::isfinite(a)) { area_uv += std::abs(a); oriented += a; }
  }
  if (!(area3 > 0) || !(area_uv > 0)) return tail;
  const double scale = std::sqrt(area_uv / area3), sign = oriented >= 0 ? 1 : -1;
  struct Term { double value; uint32_t t; double stretch; };
  std::vector<Term> terms;
  double sum = 0;
  for (size_t t = 0; t < n; ++t) {
    const double a = triangle_area(soup, t);
    geometry::SanderStretch st;
    if (!(a > 0) || !geometry::sander_stretch(soup.corner(t, 0), soup.corner(t, 1),
                                             soup.corner(t, 2), uvs[t], st))
      continue;
    const double l2_sq = 0.5 * (st.big * st.big + st.small * st.small);
    terms.push_back({a * l2_sq, uint32_t(t), std::sqrt(l2_sq) * scale});
    sum += a * l2_sq;
  }
  std::sort(terms.begin(), terms.end(), [](const Term& x, const Term& y) { return x.value > y.value; });

  for (const Term& term : terms) {
    if (tail.listed >= options.max_listed || tail.listed_share >= options.share) break;
    const size_t t = term.t;
    TailTriangle tri;
    tri.triangle = term.t;
    tri.share = term.value / sum;
    tri.stretch = term.stretch;
    const double a3 = triangle_area(soup, t);
    const double auv = 0.5 * cross(uvs[t][1] - uvs[t][0], uvs[t][2] - uvs[t][0]);
    tri.area_ratio = sign * auv / (a3 * scale * scale);
    tri.flipped = tri.area_ratio < 0;
    tri.aspect_3d = triangle_aspect(soup.corner(t, 0), soup.corner(t, 1), soup.corner(t, 2));
    bool missed = false, split = false, corrected = false;
    for (int k = 0; k < 3; ++k) {
      const size_t c = 3 * t + k;
      if (c < landing.missed.size()) missed |= landing.missed[c] != 0;
      if (c < landing.first_chart.size()) {
        split |= landing.first_chart[c] != landing.first_chart[3 * t];
        if (c < landing.final_chart.size()) corrected |= landing.final_chart[c] != landing.first_chart[c];
      }
    }
    size_t cls = 5;
    if (tri.aspect_3d < options.sliver_aspect) cls = 0;
    else if (missed) cls = 1;
    else if (split) cls = 2;
    else if (corrected) cls = 3;
    else if (flag(flags.chart_border, t)) cls = 4;
    tri.cls = kClasses[cls];
    ++tail.class_count[cls];
    tail.class_share[cls] += tri.share;
    ++tail.listed;
    tail.listed_share += tri.share;
    if (tail.worst.size() < options.max_detailed) tail.worst.push_back(tri);
  }
  return tail;
}

nlohmann::json StretchTail::to_json() const {
  nlohmann::json by_class = nlohmann::json::object();
  for (size_t i = 0; i < classes.size(); ++i)
    if (class_count[i]) by_class[classes[i]] = {{"triangles", class_count[i]}, {"share", class_share[i]}};
  nlohmann::json list = nlohmann::json::array();
  for (const TailTriangle& t : worst)
    list.push_back({{"triangle", t.triangle}, {"class", t.cls}, {"share", t.share},
                    {"stretch", t.stretch}, {"area_ratio", t.area_ratio},
                    {"aspect_3d", t.aspect_3d}, {"flipped", t.flipped}});
  return {{"listed", listed}, {"listed_share", listed_share},
          {"by_class", by_class}, {"worst", list}};
}

}  // namespace soupuv::quality
