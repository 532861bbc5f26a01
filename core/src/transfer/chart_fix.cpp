#include "soupuv/transfer/chart_fix.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>

#include "soupuv/transfer/transfer.h"

namespace soupuv::transfer {

namespace {

double uv_area(Vec2 a, Vec2 b, Vec2 c) { return 0.5 * std::abs(cross(b - a, c - a)); }

// UV units per 3D length over the whole atlas, when the atlas does not say.
double atlas_scale(const TriMesh& mesh, const atlas::Atlas& atlas) {
  if (atlas.uv_per_length > 0) return atlas.uv_per_length;
  double a3 = 0, auv = 0;
  for (size_t f = 0; f < mesh.faces.size(); ++f) {
    const auto& t = mesh.faces[f];
    a3 += 0.5 * norm(cross(mesh.vertices[t[1]] - mesh.vertices[t[0]],
                           mesh.vertices[t[2]] - mesh.vertices[t[0]]));
    auv += uv_area(atlas.face_uvs[f][0], atlas.face_uvs[f][1], atlas.face_uvs[f][2]);
  }
  return a3 > 0 ? std::sqrt(auv / a3) : 1.0;
}

// Barycentric coordinates of p projected onto the plane of face f (negative
// outside the face): evaluating the face's UVs with them extends the chart's
// map linearly across its boundary.
std::array<double, 3> plane_barycentric(const TriMesh& mesh, int f, Vec3 p) {
  const auto& t = mesh.faces[f];
  Vec3 a = mesh.vertices[t[0]], e1 = mesh.vertices[t[1]] - a, e2 = mesh.vertices[t[2]] - a;
  Vec3 q = p - a;
  double d11 = dot(e1, e1), d12 = dot(e1, e2), d22 = dot(e2, e2);
  double det = d11 * d22 - d12 * d12;
  if (!(det > 0)) return {1, 0, 0};
  double q1 = dot(q, e1), q2 = dot(q, e2);
  double v = (d22 * q1 - d12 * q2) / det, w = (d11 * q2 - d12 * q1) / det;
  return {1 - v - w, v, w};
}

}  // namespace

ChartFixResult fix_chart_boundaries(const Soup& soup, const proxy::ProxyMesh& proxy,
                                    const atlas::Atlas& atlas, std::vector<geometry::SurfacePoint>& landing,
                                    std::vector<std::array<Vec2, 3>>& corner_uvs,
                                    Progress& progress,
                                    const std::vector<geometry::AdjacentPair>* neighbours) {
  ChartFixResult r;
  const TriMesh& mesh = proxy.mesh;
  auto chart_of = [&](size_t corner) { return atlas.face_chart[landing[corner].face]; };

  std::vector<uint32_t> mixed;
  for (size_t t = 0; t < soup.triangles.size(); ++t) {
    int c0 = chart_of(3 * t), c1 = chart_of(3 * t + 1), c2 = chart_of(3 * t + 2);
    if (c0 != c1 || c0 != c2) mixed.push_back(uint32_t(t));
  }
  r.multi_chart_triangles = mixed.size();
  if (mixed.empty()) return r;

  // One BVH per chart that some mixed triangle names, built on demand.
  std::vector<std::vector<int>> chart_faces(atlas.chart_count);
  for (size_t f = 0; f < mesh.faces.size(); ++f) chart_faces[atlas.face_chart[f]].push_back(int(f));
  std::map<int, std::unique_ptr<geometry::SurfaceHitBvh>> chart_bvh;
  auto bvh_of = [&](int chart) -> const geometry::SurfaceHitBvh& {
    auto& slot = chart_bvh[chart];
    if (!slot) slot = std::make_unique<geometry::SurfaceHitBvh>(mesh, chart_faces[chart]);
    return *slot;
  };

  const double scale = atlas_scale(mesh, atlas);
  const double scale2 = scale * scale;
  // The orientation a continuous map gives the soup's winding: that of the
  // triangles that landed on one chart.
  double oriented = 0;
  for (size_t t = 0; t < soup.triangles.size(); ++t) {
    const auto& uv = corner_uvs[t];
    if (chart_of(3 * t) == chart_of(3 * t + 1) && chart_of(3 * t) == chart_of(3 * t + 2))
      oriented += cross(uv[1] - uv[0], uv[2] - uv[0]);
  }
  const double sign = oriented >= 0 ? 1 : -1;

  // Candidates per mixed triangle: each of its corners' charts, with the
  // corners on other charts moved onto it, and the cost of that choice.
  struct Candidate {
    int chart = -1;
    std::array<geometry::SurfacePoint, 3> land;
    std::array<Vec2, 3> uv;
    double cost = 0;
  };
  std::vector<std::array<Candidate, 3>> candidates(mixed.size());
  for (size_t i = 0; i < mixed.size(); ++i) {
    if ((i & 1023) == 0) progress.update("transfer", 0.8 + 0.15 * double(i) / double(mixed.size()));
    const uint32_t t = mixed[i];
    const double area3 = triangle_area(soup, t);
    int charts[3] = {chart_of(3 * t), chart_of(3 * t + 1), chart_of(3 * t + 2)};
    for (int k = 0; k < 3; ++k) {
      int chart = charts[k];
      if ((k > 0 && chart == charts[0]) || (k > 1 && chart == charts[1])) continue;  // tried
      Candidate& cand = candidates[i][k];
      cand.chart = chart;
      for (int j = 0; j < 3; ++j) {
        if (charts[j] == chart) {
          cand.land[j] = landing[3 * t + j];
          cand.uv[j] = atlas_uv(atlas, cand.land[j]);
          continue;
        }
        // The closest point of the chart sits on its boundary; the paper
        // takes its UV, which squashes the triangle against the seam. We
        // extend the boundary face's linear map to the landing point instead
        // (continuous across the seam, exact where the proxy is flat), as
        // long as that stays within four face sizes of the boundary.
        const Vec3 p = landing[3 * t + j].point;
        cand.land[j] = bvh_of(chart).closest_point(p);
        cand.uv[j] = atlas_uv(atlas, cand.land[j]);
        const auto& f = mesh.faces[cand.land[j].face];
        double size = std::max({norm(mesh.vertices[f[1]] - mesh.vertices[f[0]]),
                                norm(mesh.vertices[f[2]] - mesh.vertices[f[1]]),
                                norm(mesh.vertices[f[0]] - mesh.vertices[f[2]])});
        if (norm(p - cand.land[j].point) <= 4 * size) {
          geometry::SurfacePoint extended = cand.land[j];
          extended.bary = plane_barycentric(mesh, cand.land[j].face, p);
          cand.uv[j] = atlas_uv(atlas, extended);
          // A chart packed against the atlas border must not extend past it.
          cand.uv[j].x = std::clamp(cand.uv[j].x, 0.0, 1.0);
          cand.uv[j].y = std::clamp(cand.uv[j].y, 0.0, 1.0);
        }
      }
      // §8's measure as a log ratio of UV area (at the global scale) to 3D
      // area: a triangle squashed to a tenth costs 2.3, a collapsed one ~14,
      // so agreeing with the neighbours never buys a degenerate triangle; a
      // flipped one costs 4 more.
      const double signed_uv = 0.5 * cross(cand.uv[1] - cand.uv[0], cand.uv[2] - cand.uv[0]);
      const double ratio = area3 > 0 ? std::abs(signed_uv) / scale2 / area3 : 1;
      cand.cost = std::abs(std::log(std::max(ratio, 1e-6)));
      if (sign * signed_uv < 0) cand.cost += 4;
    }
  }

  // The label of each triangle: its chart, or for a mixed one the chosen
  // candidate. Paper's rule: the least cost. With neighbours, iterated
  // conditional modes add one per neighbour on another chart, so the seam
  // runs along soup edges instead of zig-zagging through the band of mixed
  // triangles (every neighbour pair on two charts is a cut in the texture).
  std::vector<int> label(soup.triangles.size());
  std::vector<int32_t> mixed_index(soup.triangles.size(), -1);
  for (size_t t = 0; t < soup.triangles.size(); ++t) label[t] = chart_of(3 * t);
  auto best_alone = [&](size_t i) {
    int best = -1;
    for (int k = 0; k < 3; ++k)
      if (candidates[i][k].chart >= 0 && (best < 0 || candidates[i][k].cost < candidates[i][best].cost))
        best = k;
    return best;
  };
  std::vector<int> choice(mixed.size());
  for (size_t i = 0; i < mixed.size(); ++i) {
    mixed_index[mixed[i]] = int32_t(i);
    choice[i] = best_alone(i);
    label[mixed[i]] = candidates[i][choice[i]].chart;
  }
  if (neighbours && !neighbours->empty()) {
    const size_t n = soup.triangles.size();
    std::vector<uint32_t> start(n + 1, 0);
    for (const auto& p : *neighbours) { ++start[p.a + 1]; ++start[p.b + 1]; }
    for (size_t i = 0; i < n; ++i) start[i + 1] += start[i];
    std::vector<uint32_t> fill(start.begin(), start.end() - 1), nbr(start[n]);
    for (const auto& p : *neighbours) { nbr[fill[p.a]++] = p.b; nbr[fill[p.b]++] = p.a; }
    for (int sweep = 0; sweep < 8; ++sweep) {
      size_t changed = 0;
      for (size_t i = 0; i < mixed.size(); ++i) {
        const uint32_t t = mixed[i];
        int best = choice[i];
        double best_cost = INFINITY;
        for (int k = 0; k < 3; ++k) {
          const Candidate& c = candidates[i][k];
          if (c.chart < 0) continue;
          double cost = c.cost;
          for (uint32_t e = start[t]; e < start[t + 1]; ++e) cost += label[nbr[e]] != c.chart;
          if (cost < best_cost) { best_cost = cost; best = k; }
        }
        if (best != choice[i]) {
          choice[i] = best;
          label[t] = candidates[i][best].chart;
          ++changed;
        }
      }
      if (changed == 0) break;
    }
  }
  for (size_t i = 0; i < mixed.size(); ++i) {
    const uint32_t t = mixed[i];
    const Candidate& c = candidates[i][choice[i]];
    bool changed = false;
    for (int j = 0; j < 3; ++j) {
      changed |= c.land[j].face != landing[3 * t + j].face;
      landing[3 * t + j] = c.land[j];
    }
    corner_uvs[t] = c.uv;
    r.corrected_triangles += changed;
  }
  return r;
}

}  // namespace soupuv::transfer
