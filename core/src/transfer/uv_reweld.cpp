#include "soupuv/transfer/uv_reweld.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "soupuv/errors.h"
#include "transfer/sym_dirichlet.h"
#include "transfer/uv_vertices.h"

namespace soupuv::transfer {

nlohmann::json UvReweldResult::diagnostics() const {
  return {{"split_vertices", split_vertices}, {"joined_vertices", joined_vertices},
          {"joins", joins},                   {"refused", refused},
          {"moved_corners", moved_corners},   {"seconds", seconds}};
}

namespace {

using detail::RestTriangle;
// The UV repair's floor: a triangle keeps 1/1000 of its isometric UV area.
constexpr double kMinAreaRatio = 1e-3;

// The copies of one UV vertex that sit at one UV.
struct Cluster {
  Vec2 uv;
  std::vector<uint32_t> corners;
  double weight = 0;  // area of their triangles: the mean leans to the larger side
};

class Joiner {
 public:
  Joiner(const std::vector<RestTriangle>& rest, std::vector<std::array<Vec2, 3>>& uvs,
         const UvReweldOptions& options)
      : rest_(rest), uvs_(uvs), options_(options) {}

  // Cost of moving `corners` to q (their triangles' energy), or +inf when a
  // triangle would fold, collapse or stretch past the limit.
  double cost(const std::vector<uint32_t>& corners, Vec2 q) const {
    double sum = 0;
    for (uint32_t c : corners) {
      const uint32_t t = c / 3;
      const RestTriangle& r = rest_[t];
      if (!r.valid) continue;  // no 3D shape to keep
      std::array<Vec2, 3> moved = uvs_[t];
      moved[c % 3] = q;
      const double det_before = detail::jacobian(r, uvs_[t]).det();
      const double det_after = detail::jacobian(r, moved).det();
      const bool was_fine = det_before >= kMinAreaRatio;
      if (det_after < kMinAreaRatio && (was_fine || det_after < det_before))
        return std::numeric_limits<double>::infinity();
      const double after = detail::energy(r, moved);
      const double before = detail::energy(r, uvs_[t]);
      if (after > std::max(before, options_.max_energy_density * r.area))
        return std::numeric_limits<double>::infinity();
      if (std::isfinite(after)) sum += after;
    }
    return sum;
  }

  // Joins clusters a and b at their best common UV; false if none is allowed.
  bool join(Cluster& a, Cluster& b) {
    std::vector<uint32_t> both = a.corners;
    both.insert(both.end(), b.corners.begin(), b.corners.end());
    const double w = a.weight + b.weight;
    const Vec2 mean = w > 0 ? (a.weight / w) * a.uv + (b.weight / w) * b.uv : 0.5 * (a.uv + b.uv);
    Vec2 best{0, 0};
    double best_cost = std::numeric_limits<double>::infinity();
    for (Vec2 q : {mean, a.uv, b.uv}) {
      const double c = cost(both, q);
      if (c < best_cost) { best_cost = c; best = q; }
    }
    if (!std::isfinite(best_cost)) return false;
    for (uint32_t c : both) uvs_[c / 3][c % 3] = best;
    a.uv = best;
    a.corners = std::move(both);
    a.weight = w;
    b.corners.clear();
    return true;
  }

 private:
  const std::vector<RestTriangle>& rest_;
  std::vector<std::array<Vec2, 3>>& uvs_;
  const UvReweldOptions& options_;
};

}  // namespace

UvReweldResult reweld_uvs(const Soup& soup, const quality::Weld& groups,
                          const std::vector<int>& triangle_chart, double uv_per_length,
                          std::vector<std::array<Vec2, 3>>& uvs, const UvReweldOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  const size_t n = soup.triangles.size();
  if (uvs.size() != n || triangle_chart.size() != n || groups.corner_vertex.size() != 3 * n)
    throw Error(ErrorCode::internal, "uv reweld: sizes of soup, groups, charts and UVs differ");
  UvReweldResult r;
  if (n == 0 || !(uv_per_length > 0)) return r;

  // The dominant orientation, as the UV repair and the metrics take it.
  double oriented = 0;
  for (const auto& uv : uvs) oriented += cross(uv[1] - uv[0], uv[2] - uv[0]);
  const double orientation = oriented >= 0 ? 1 : -1;
  std::vector<RestTriangle> rest(n);
  for (size_t t = 0; t < n; ++t)
    rest[t] = detail::rest_triangle(soup.corner(t, 0), soup.corner(t, 1), soup.corner(t, 2),
                                    uv_per_length, orientation);

  const detail::UvVertices verts = detail::uv_vertices(groups, triangle_chart);
  const std::vector<std::array<Vec2, 3>> before = uvs;
  Joiner joiner(rest, uvs, options);
  std::vector<uint8_t> counted(verts.count(), 0);
  for (int sweep = 0; sweep < options.sweeps; ++sweep) {
    size_t joins_this_sweep = 0;
    r.refused = 0;  // what the last sweep still refused
    for (uint32_t v = 0; v < verts.count(); ++v) {
      std::vector<Cluster> clusters;
      for (uint32_t e = verts.start[v]; e < verts.start[v + 1]; ++e) {
        const uint32_t c = verts.corners[e];
        const Vec2 p = uvs[c / 3][c % 3];
        auto it = std::find_if(clusters.begin(), clusters.end(),
                               [&](const Cluster& k) { return k.uv.x == p.x && k.uv.y == p.y; });
        if (it == clusters.end()) it = clusters.insert(clusters.end(), Cluster{p, {}, 0});
        it->corners.push_back(c);
        it->weight += triangle_area(soup, c / 3);
      }
      if (clusters.size() < 2) continue;
      if (!counted[v]) { counted[v] = 1; ++r.split_vertices; }
      // Closest pairs first; a refused pair is not tried again this sweep.
      std::vector<std::pair<size_t, size_t>> refused;
      for (;;) {
        double best = std::numeric_limits<double>::infinity();
        size_t ia = 0, ib = 0;
        for (size_t i = 0; i < clusters.size(); ++i)
          for (size_t j = i + 1; j < clusters.size(); ++j) {
            if (clusters[i].corners.empty() || clusters[j].corners.empty()) continue;
            if (std::find(refused.begin(), refused.end(), std::make_pair(i, j)) != refused.end()) continue;
            const Vec2 gap = clusters[i].uv - clusters[j].uv;
            const double d = dot(gap, gap);
            if (d < best) { best = d; ia = i; ib = j; }
          }
        if (!std::isfinite(best)) break;
        if (joiner.join(clusters[ia], clusters[ib])) {
          ++r.joins;
          ++joins_this_sweep;
        } else {
          refused.push_back({ia, ib});
          ++r.refused;
        }
      }
    }
    if (joins_this_sweep == 0) break;
  }
  for (uint32_t v = 0; v < verts.count(); ++v) {
    if (!counted[v]) continue;
    bool one = true;
    const uint32_t c0 = verts.corners[verts.start[v]];
    for (uint32_t e = verts.start[v]; e < verts.start[v + 1]; ++e) {
      const uint32_t c = verts.corners[e];
      one &= uvs[c / 3][c % 3].x == uvs[c0 / 3][c0 % 3].x && uvs[c / 3][c % 3].y == uvs[c0 / 3][c0 % 3].y;
    }
    r.joined_vertices += one;
  }
  for (size_t c = 0; c < 3 * n; ++c)
    r.moved_corners += uvs[c / 3][c % 3].x != before[c / 3][c % 3].x ||
                       uvs[c / 3][c % 3].y != before[c / 3][c % 3].y;
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

}  // namespace soupuv::transfer
