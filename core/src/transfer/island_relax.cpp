#include "soupuv/transfer/island_relax.h"

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "soupuv/quality/uv_metrics.h"
#include "transfer/island_mesh.h"
#include "transfer/slim.h"
#include "transfer/sym_dirichlet.h"
#include "transfer/uv_overlap.h"

namespace soupuv::transfer {

nlohmann::json IslandRelaxResult::diagnostics(size_t max_islands) const {
  nlohmann::json list = nlohmann::json::array();
  for (size_t i = 0; i < per_island.size() && i < max_islands; ++i) {
    const IslandFigures& f = per_island[i];
    list.push_back({{"triangles", f.triangles},
                    {"vertices", f.vertices},
                    {"free_vertices", f.free_vertices},
                    {"stretch_l2_before", f.stretch_l2_before},
                    {"stretch_l2_after", f.stretch_l2_after},
                    {"energy_before", f.energy_before},
                    {"energy_after", f.energy_after},
                    {"iterations", f.iterations},
                    {"l2_iterations", f.l2_iterations},
                    {"choice", f.choice},
                    {"overlap_change", f.overlap_change},
                    {"outcome", f.outcome},
                    {"seconds", f.seconds}});
  }
  return {{"islands", islands},
          {"relaxed", relaxed},
          {"rejected_no_gain", rejected_no_gain},
          {"rejected_flipped", rejected_flipped},
          {"rejected_outside", rejected_outside},
          {"rejected_overlap", rejected_overlap},
          {"skipped_small", skipped_small},
          {"skipped_fixed", skipped_fixed},
          {"snapped_corners", snapped_corners},
          {"moved_corners", moved_corners},
          {"stretch_l2_before", stretch_l2_before},
          {"stretch_l2_after", stretch_l2_after},
          {"overlap_texels_before", overlap_texels_before},
          {"overlap_texels_after", overlap_texels_after},
          {"per_island", list},
          {"seconds", seconds}};
}

namespace {

using Clock = std::chrono::steady_clock;
using detail::RestTriangle;

struct MapScale {
  double uv_per_length = 0;  // sqrt(UV area / 3D area): the L2 metric's normalisation
  double orientation = 1;    // the dominant (area-weighted) UV orientation
  double collapse_ratio = 0; // UV / 3D area below which a triangle counts as collapsed
  // The L2 metric's sums: squared L2 = (S / W) (U / A3) with S = sum of A3 x
  // Sander's squared stretch and W its weight (triangles with a UV map), U
  // the UV area and A3 the 3D area of all triangles.
  double s = 0, w = 0, u = 0, a3 = 0;
  double l2() const { return w > 0 && a3 > 0 ? std::sqrt(s / w * u / a3) : 0; }
};

double uv_area2(const std::array<Vec2, 3>& uv) { return cross(uv[1] - uv[0], uv[2] - uv[0]); }

// Area-weighted sum of Sander's squared L2 stretch and its weight.
void add_l2(const Soup& soup, size_t t, const std::array<Vec2, 3>& uv, double& sum, double& weight) {
  const double a = triangle_area(soup, t);
  double big, small;
  if (!(a > 0) || !quality::stretch_singular_values(soup.corner(t, 0), soup.corner(t, 1),
                                                    soup.corner(t, 2), uv, big, small))
    return;
  sum += a * 0.5 * (big * big + small * small);
  weight += a;
}

MapScale map_scale(const Soup& soup, const std::vector<std::array<Vec2, 3>>& uvs) {
  double a3 = 0, auv = 0, oriented = 0;
  for (size_t t = 0; t < uvs.size(); ++t) {
    a3 += triangle_area(soup, t);
    const double a = 0.5 * uv_area2(uvs[t]);
    auv += std::abs(a);
    oriented += a;
  }
  MapScale s;
  for (size_t t = 0; t < uvs.size(); ++t) add_l2(soup, t, uvs[t], s.s, s.w);
  s.u = auv;
  s.a3 = a3;
  s.uv_per_length = a3 > 0 ? std::sqrt(auv / a3) : 0;
  s.orientation = oriented >= 0 ? 1 : -1;
  s.collapse_ratio = a3 > 0 ? 1e-6 * auv / a3 : 0;
  return s;
}

// The metric's flipped test (quality/uv_metrics.cpp).
bool flipped(const Soup& soup, size_t t, const std::array<Vec2, 3>& uv, const MapScale& s) {
  const double a3 = triangle_area(soup, t);
  const double a = 0.5 * uv_area2(uv);
  return a3 > 0 && (s.orientation * a < 0 || std::abs(a) <= s.collapse_ratio * a3);
}

double map_l2(const Soup& soup, const std::vector<std::array<Vec2, 3>>& uvs) {
  return map_scale(soup, uvs).l2();
}

bool inside_unit_square(Vec2 p) { return p.x >= 0 && p.x <= 1 && p.y >= 0 && p.y <= 1; }

// The relaxed island put back where it was: the rigid motion that best
// matches its start (2D Procrustes), so an island with nothing fixed does
// not drift or turn into its neighbours; then, if it pokes out of [0,1]^2,
// moved (and if it is too big, shrunk) into it. Returns the scale applied.
double place_like(const std::vector<Vec2>& start, std::vector<Vec2>& uv) {
  const size_t n = uv.size();
  Vec2 c0{0, 0}, c1{0, 0};
  for (size_t i = 0; i < n; ++i) {
    c0 = c0 + start[i];
    c1 = c1 + uv[i];
  }
  c0 = c0 * (1.0 / n);
  c1 = c1 * (1.0 / n);
  double sin_sum = 0, cos_sum = 0;
  for (size_t i = 0; i < n; ++i) {
    const Vec2 a = uv[i] - c1, b = start[i] - c0;
    cos_sum += dot(a, b);
    sin_sum += cross(a, b);
  }
  const double angle = std::atan2(sin_sum, cos_sum), c = std::cos(angle), s = std::sin(angle);
  Vec2 lo{1e300, 1e300}, hi{-1e300, -1e300};
  for (Vec2& p : uv) {
    const Vec2 a = p - c1;
    p = Vec2{c * a.x - s * a.y, s * a.x + c * a.y} + c0;
    lo = {std::min(lo.x, p.x), std::min(lo.y, p.y)};
    hi = {std::max(hi.x, p.x), std::max(hi.y, p.y)};
  }
  const double extent = std::max(hi.x - lo.x, hi.y - lo.y);
  const double scale = extent > 1 ? 1 / extent : 1;
  if (scale < 1)
    for (Vec2& p : uv) p = lo + (p - lo) * scale;
  hi = lo + (hi - lo) * scale;
  const Vec2 shift{lo.x < 0 ? -lo.x : (hi.x > 1 ? 1 - hi.x : 0), lo.y < 0 ? -lo.y : (hi.y > 1 ? 1 - hi.y : 0)};
  for (Vec2& p : uv) p = Vec2{std::clamp(p.x + shift.x, 0.0, 1.0), std::clamp(p.y + shift.y, 0.0, 1.0)};
  return scale;
}

// One island relaxed on its own; `relaxed` gets its triangles' new corner
// UVs when the outcome is "relaxed" (pending the overlap test).
struct IslandRun {
  IslandFigures figures;
  // The admissible results, most relaxed first (the L2 descent's rounds,
  // last first, then SLIM's alone) with their island L2: the overlap test
  // takes the first that fits (a more relaxed island is often larger and
  // overlaps more).
  std::vector<std::vector<std::array<Vec2, 3>>> choices;
  std::vector<double> choice_l2;
};

IslandRun relax_one(const Soup& soup, const std::vector<uint32_t>& island,
                    const detail::IslandMeshes& meshes,
                    const std::vector<std::array<Vec2, 3>>& uvs, const MapScale& scale,
                    const IslandRelaxOptions& options) {
  const auto t0 = Clock::now();
  IslandRun run;
  IslandFigures& f = run.figures;
  f.triangles = island.size();
  // Local vertices, in order of first use.
  std::vector<uint32_t> global;
  std::vector<std::array<uint32_t, 3>> triangles(island.size());
  {
    std::vector<std::pair<uint32_t, uint32_t>> seen;  // (global, local), sorted later
    std::vector<uint32_t> corner_vertices;
    corner_vertices.reserve(3 * island.size());
    for (uint32_t t : island)
      for (int k = 0; k < 3; ++k) corner_vertices.push_back(meshes.vertex_of_corner[3 * t + k]);
    global = corner_vertices;
    std::sort(global.begin(), global.end());
    global.erase(std::unique(global.begin(), global.end()), global.end());
    for (size_t i = 0; i < island.size(); ++i)
      for (int k = 0; k < 3; ++k)
        triangles[i][k] = uint32_t(std::lower_bound(global.begin(), global.end(),
                                                    corner_vertices[3 * i + k]) - global.begin());
  }
  f.vertices = global.size();
  std::vector<Vec2> uv(global.size());
  for (size_t v = 0; v < global.size(); ++v) uv[v] = meshes.vertex_uv[global[v]];

  // Triangles flipped, collapsed or 3D-degenerate at the start stay out of
  // the energy, and their corners stay where they are.
  std::vector<RestTriangle> rest(island.size());
  std::vector<uint8_t> fixed(global.size(), 0), was_flipped(island.size(), 0);
  double sum_before = 0, weight_before = 0, uv_before = 0, valid_s = 0, valid_u = 0;
  for (size_t i = 0; i < island.size(); ++i) {
    const uint32_t t = island[i];
    was_flipped[i] = flipped(soup, t, uvs[t], scale);
    add_l2(soup, t, uvs[t], sum_before, weight_before);
    uv_before += 0.5 * std::abs(uv_area2(uvs[t]));
    rest[i] = detail::rest_triangle(soup.corner(t, 0), soup.corner(t, 1), soup.corner(t, 2),
                                    scale.uv_per_length, scale.orientation);
    const std::array<Vec2, 3> start{uv[triangles[i][0]], uv[triangles[i][1]], uv[triangles[i][2]]};
    if (!rest[i].valid || was_flipped[i] || !std::isfinite(detail::energy(rest[i], start))) {
      rest[i].valid = false;
      for (int k = 0; k < 3; ++k) fixed[triangles[i][k]] = 1;
    } else {
      double w = 0;
      add_l2(soup, t, uvs[t], valid_s, w);
      valid_u += 0.5 * std::abs(uv_area2(uvs[t]));
    }
  }
  // The island's L2 at the map's normalisation (the map's UV area with the
  // island's own in it).
  auto island_l2 = [&](double sum, double weight, double uv_area) {
    const double u = scale.u - uv_before + uv_area;
    return weight > 0 ? std::sqrt(sum / weight * u / scale.a3) : 0;
  };
  f.stretch_l2_before = island_l2(sum_before, weight_before, uv_before);
  f.free_vertices = size_t(std::count(fixed.begin(), fixed.end(), 0));
  auto finish = [&](const char* outcome) {
    f.outcome = outcome;
    f.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    return run;
  };
  if (island.size() < options.min_island_triangles) return finish("small");
  if (f.free_vertices == 0) return finish("fixed");

  detail::SlimOptions so;
  so.max_iterations = options.max_iterations;
  so.min_relative_decrease = options.min_relative_decrease;
  const std::vector<Vec2> start = uv;
  const detail::SlimResult slim = detail::slim_relax(triangles, rest, fixed, uv, so);
  double area3 = 0;
  for (uint32_t t : island) area3 += triangle_area(soup, t);
  const double per_area = area3 > 0 ? 1 / (area3 * scale.uv_per_length * scale.uv_per_length) : 0;
  f.energy_before = slim.energy_before * per_area;
  f.energy_after = slim.energy_after * per_area;
  f.iterations = slim.iterations;
  if (!slim.started) return finish("fixed");

  // A result placed back and checked: its outcome, and its corner UVs.
  const double map_before = scale.l2();
  auto judge = [&](std::vector<Vec2> placed, std::vector<std::array<Vec2, 3>>& corners, double& l2) {
    place_like(start, placed);
    corners.resize(island.size());
    double sum_after = 0, weight_after = 0, uv_after = 0;
    bool outside = false, new_flip = false;
    for (size_t i = 0; i < island.size(); ++i) {
      for (int k = 0; k < 3; ++k) {
        corners[i][k] = placed[triangles[i][k]];
        outside |= !inside_unit_square(corners[i][k]);
      }
      new_flip |= !was_flipped[i] && flipped(soup, island[i], corners[i], scale);
      add_l2(soup, island[i], corners[i], sum_after, weight_after);
      uv_after += 0.5 * std::abs(uv_area2(corners[i]));
    }
    l2 = island_l2(sum_after, weight_after, uv_after);
    // The whole map's L2 with this island changed alone.
    const double map_after = std::sqrt((scale.s - sum_before + sum_after) /
                                       (scale.w - weight_before + weight_after) *
                                       (scale.u - uv_before + uv_after) / scale.a3);
    if (new_flip) return "flipped";
    if (outside) return "outside";
    if (!(l2 < f.stretch_l2_before) || !(map_after < map_before)) return "no_gain";
    return "relaxed";
  };
  std::vector<std::array<Vec2, 3>> slim_corners;
  double slim_l2 = 0;
  const std::string slim_outcome = judge(uv, slim_corners, slim_l2);
  if (slim_outcome == "relaxed") {
    run.choices.push_back(std::move(slim_corners));
    run.choice_l2.push_back(slim_l2);
  }

  // Then the metric itself, with the rest of the map held as it is, in
  // rounds of growing length; each round's result is one more choice.
  // (The rest shapes are at scale s: their S terms are s^4 times the metric's.)
  const double s4 = std::pow(scale.uv_per_length, 4);
  std::string last_outcome = slim_outcome;
  double last_l2 = slim_l2;
  for (int round = 0, done = 0; done < options.l2_iterations; ++round) {
    detail::SlimOptions lo = so;
    lo.max_iterations = std::min(options.l2_iterations - done, 10 << (2 * round));  // 10, 40, 160, ...
    lo.min_relative_decrease = 1e-8;
    const detail::SlimResult l2 = detail::l2_relax(triangles, rest, fixed, uv, (scale.s - valid_s) * s4,
                                                   scale.u - valid_u, lo);
    f.l2_iterations += l2.iterations;
    done += lo.max_iterations;
    if (l2.iterations == 0) break;
    std::vector<std::array<Vec2, 3>> corners;
    last_outcome = judge(uv, corners, last_l2);
    if (last_outcome == "relaxed") {
      run.choices.insert(run.choices.begin(), std::move(corners));
      run.choice_l2.insert(run.choice_l2.begin(), last_l2);
    }
    if (l2.iterations < lo.max_iterations) break;  // converged
  }
  if (!run.choices.empty()) {
    f.stretch_l2_after = run.choice_l2[0];
    return finish("relaxed");
  }
  f.stretch_l2_after = last_l2;
  return finish(last_outcome.c_str());
}

}  // namespace

IslandRelaxResult relax_islands(const Soup& soup, const quality::Weld& weld,
                                std::vector<std::array<Vec2, 3>>& corner_uvs,
                                const IslandRelaxOptions& options, Progress& progress) {
  const auto t0 = Clock::now();
  IslandRelaxResult r;
  progress.update("island_relax", 0);
  const MapScale scale = map_scale(soup, corner_uvs);
  r.stretch_l2_before = r.stretch_l2_after = map_l2(soup, corner_uvs);
  const double texel = 1.0 / std::max(1, options.texture_size);
  const detail::IslandMeshes meshes = detail::island_meshes(
      soup, weld, options.also_weld, corner_uvs, texel,
      options.uv_per_length > 0 ? options.uv_per_length : scale.uv_per_length);
  r.islands = meshes.islands.size();
  r.snapped_corners = meshes.snapped_corners;

  // Islands relax independently (largest first, so the big ones start early).
  std::vector<IslandRun> runs(meshes.islands.size());
  const int threads = options.threads > 0 ? options.threads : omp_get_max_threads();
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
  for (long i = 0; i < long(runs.size()); ++i) {
    if (progress.canceled()) continue;
    runs[i] = relax_one(soup, meshes.islands[i], meshes, corner_uvs, scale, options);
  }
  progress.update("island_relax", 0.9);  // throws when canceled

  // Accept island by island against the layout as it stands: the overlap
  // excess must not grow.
  detail::OverlapGrid grid(options.overlap_grid);
  for (const auto& t : corner_uvs) grid.add(t, +1);
  r.overlap_texels_before = grid.excess();
  for (size_t i = 0; i < runs.size(); ++i) {
    IslandFigures& f = runs[i].figures;
    const std::vector<uint32_t>& island = meshes.islands[i];
    if (f.outcome == "relaxed") {
      f.outcome = "overlap";
      for (size_t c = 0; c < runs[i].choices.size() && f.outcome == "overlap"; ++c) {
        const auto& relaxed = runs[i].choices[c];
        const long before = grid.excess();
        for (uint32_t t : island) grid.add(corner_uvs[t], -1);
        for (const auto& t : relaxed) grid.add(t, +1);
        f.overlap_change = grid.excess() - before;
        if (f.overlap_change > 0) {
          for (const auto& t : relaxed) grid.add(t, -1);
          for (uint32_t t : island) grid.add(corner_uvs[t], +1);
          continue;
        }
        f.outcome = "relaxed";
        f.stretch_l2_after = runs[i].choice_l2[c];
        f.choice = int(c);
        for (size_t j = 0; j < island.size(); ++j)
          for (int k = 0; k < 3; ++k) {
            Vec2& uv = corner_uvs[island[j]][k];
            const Vec2 next = relaxed[j][k];
            r.moved_corners += uv.x != next.x || uv.y != next.y;
            uv = next;
          }
      }
    }
    if (f.outcome == "relaxed") ++r.relaxed;
    else if (f.outcome == "no_gain") ++r.rejected_no_gain;
    else if (f.outcome == "flipped") ++r.rejected_flipped;
    else if (f.outcome == "outside") ++r.rejected_outside;
    else if (f.outcome == "overlap") ++r.rejected_overlap;
    else if (f.outcome == "small") ++r.skipped_small;
    else ++r.skipped_fixed;
    r.per_island.push_back(f);
  }
  r.overlap_texels_after = grid.excess();
  r.stretch_l2_after = map_l2(soup, corner_uvs);
  r.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  progress.update("island_relax", 1);
  return r;
}

}  // namespace soupuv::transfer
