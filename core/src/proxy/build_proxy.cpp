// build_proxy: offset policy -> narrow band (pruned to the outer shell) -> marching cubes -> edge collapse ->
// drop inner components -> remesh -> Taubin smoothing -> lift to d = o -> measured checks.
// See soupuv/proxy/proxy.h.
#include "soupuv/proxy/proxy.h"

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>

#include "soupuv/cgal/proxy_remesh.h"
#include "soupuv/cgal/proxy_self_intersections.h"
#include "soupuv/errors.h"
#include "soupuv/proxy/collapse_short_edges.h"
#include "soupuv/proxy/components.h"
#include "soupuv/proxy/lift_to_offset.h"
#include "soupuv/proxy/marching_cubes.h"
#include "soupuv/proxy/marching_tetrahedra.h"
#include "soupuv/proxy/mesh_checks.h"
#include "soupuv/proxy/narrow_band.h"
#include "soupuv/proxy/offset_policy.h"
#include "soupuv/proxy/taubin_smooth.h"
#include "soupuv/geometry/distance_bvh.h"

namespace soupuv::proxy {
namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// Restores the caller's OpenMP thread count when the build ends.
struct ThreadScope {
  int saved = omp_get_max_threads();
  explicit ThreadScope(int threads) {
    if (threads > 0) omp_set_num_threads(threads);
  }
  ~ThreadScope() { omp_set_num_threads(saved); }
};

void validate(const Soup& soup, const ProxyOptions& o) {
  if (soup.triangles.empty()) throw Error(ErrorCode::no_triangles, "proxy: the soup has no triangles");
  for (const Tri& t : soup.triangles)
    for (uint32_t v : t) {
      if (v >= soup.positions.size()) throw Error(ErrorCode::invalid_input, "proxy: vertex index out of range");
      const Vec3& p = soup.positions[v];
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
        throw Error(ErrorCode::invalid_input, "proxy: non-finite vertex position");
    }
  if (o.offset_mode != OffsetMode::automatic && !(o.offset > 0 && std::isfinite(o.offset)))
    throw Error(ErrorCode::invalid_input, "proxy: offset must be a positive finite number");
  if (o.offset_mode == OffsetMode::automatic &&
      (o.ladder.empty() || std::any_of(o.ladder.begin(), o.ladder.end(), [](double f) { return !(f > 0); })))
    throw Error(ErrorCode::invalid_input, "proxy: the automatic ladder needs positive fractions");
  if (o.resolution < 0 || o.min_resolution < 2 || o.max_resolution < o.min_resolution ||
      o.resolution > 4096 || o.max_resolution > 4096)
    throw Error(ErrorCode::invalid_input, "proxy: resolution out of range (2 .. 4096)");
  if (o.smoothing_iterations < 0 || o.remesh_iterations < 0 || o.target_edge_length < 0)
    throw Error(ErrorCode::invalid_input, "proxy: negative iterations or edge length");
}

// Corners the soup's triangles use: what "encloses the soup" is checked on.
std::vector<Vec3> used_positions(const Soup& soup) {
  std::vector<char> used(soup.positions.size(), 0);
  for (const Tri& t : soup.triangles)
    for (uint32_t v : t) used[v] = 1;
  std::vector<Vec3> out;
  for (size_t v = 0; v < used.size(); ++v)
    if (used[v]) out.push_back(soup.positions[v]);
  return out;
}

// One extraction at a fixed offset and resolution, coarsened by our edge
// collapse when `collapse_to` > 0, outer components only. Collapsing before
// the component split keeps the split (and its BVHs) small; the collapse
// keeps every component's topology, so the split is the same.
struct Extraction {
  TriMesh mesh;
  int outer = 0, inner = 0;
  size_t raw_triangles = 0, collapsed_triangles = 0, surface_cells = 0, evaluations = 0, pruned = 0;
  double cell = 0;
  // Triangles the remeshed proxy would have (the level set's area tiled by
  // equilateral triangles of the target edge; the raw count without one).
  double estimated_triangles = 0;
  bool over_budget = false;  // then the extraction stopped there (mesh empty)
  double seconds_grid = 0, seconds_extract = 0, seconds_decimate = 0;
};

// How many triangles `mesh` becomes when remeshed to edge length `edge`
// (equilateral triangles tiling its area); its own count when edge is 0.
double remeshed_triangles(const TriMesh& mesh, double edge) {
  if (!(edge > 0)) return static_cast<double>(mesh.faces.size());
  double area = 0;
  for (const auto& f : mesh.faces)
    area += 0.5 * norm(cross(mesh.vertices[f[1]] - mesh.vertices[f[0]], mesh.vertices[f[2]] - mesh.vertices[f[0]]));
  return area / (std::sqrt(3.0) / 4 * edge * edge);
}

Extraction extract(const geometry::DistanceBvh& bvh, const Box3& box, double offset, int resolution,
                   bool cubes, bool prune, double collapse_to, size_t max_triangles, Progress& progress) {
  Extraction ex;
  Vec3 ext = box.extent();
  ex.cell = std::max({ext.x, ext.y, ext.z}) / resolution;
  auto t0 = Clock::now();
  NarrowBand band = build_narrow_band(bvh, box, offset, ex.cell, progress, prune);
  ex.pruned = band.pruned_cells;
  ex.seconds_grid = since(t0);
  ex.surface_cells = band.cells.size();
  ex.evaluations = band.distance_evaluations;
  // A cell the level set crosses holds between cell^2 / sqrt(3) (a plane
  // along a cube's diagonal) and about cell^2 of it: when even the lower
  // bound is over the budget, marching cubes (seconds at a fine grid) is
  // skipped; the exact estimate follows the extraction.
  if (collapse_to > 0 && max_triangles > 0) {
    const double area_low = static_cast<double>(band.cells.size()) * ex.cell * ex.cell / std::sqrt(3.0);
    ex.estimated_triangles = area_low / (std::sqrt(3.0) / 4 * collapse_to * collapse_to);
    if (ex.estimated_triangles > static_cast<double>(max_triangles)) {
      ex.over_budget = true;
      return ex;
    }
  }
  t0 = Clock::now();
  TriMesh raw = cubes ? marching_cubes(band, progress) : marching_tetrahedra(band, progress);
  band = NarrowBand{};
  ex.raw_triangles = raw.faces.size();
  ex.seconds_extract = since(t0);
  ex.estimated_triangles = remeshed_triangles(raw, collapse_to);
  if (max_triangles > 0 && ex.estimated_triangles > static_cast<double>(max_triangles)) {
    ex.over_budget = true;
    return ex;
  }
  if (collapse_to > 0) {
    t0 = Clock::now();
    progress.update("proxy: collapsing short edges", 0);
    // Stop at 0.6 of the target and allow 1.5 of it: CGAL's remeshing then
    // only splits or collapses a few edges to reach the target.
    raw = collapse_short_edges(raw, 0.6 * collapse_to, 1.5 * collapse_to);
    ex.collapsed_triangles = raw.faces.size();
    ex.seconds_decimate = since(t0);
  }
  t0 = Clock::now();
  Components comps = find_components(raw);
  std::vector<char> keep(raw.faces.size());
  for (size_t f = 0; f < raw.faces.size(); ++f) keep[f] = !comps.inner[comps.face_component[f]];
  for (int c = 0; c < comps.count; ++c) (comps.inner[c] ? ex.inner : ex.outer)++;
  ex.mesh = keep_faces(raw, keep);
  ex.seconds_extract += since(t0);
  return ex;
}

// Everything measured on a finished proxy mesh.
void measure(const TriMesh& mesh, const geometry::DistanceBvh& soup_bvh, const std::vector<Vec3>& soup_points,
             double offset, bool check_self_intersections, Progress& progress, ProxyResult& r) {
  Topology topo = check_topology(mesh);
  r.closed = topo.closed;
  r.manifold = topo.manifold && topo.degenerate_faces == 0;
  if (topo.degenerate_faces > 0)
    r.warnings.push_back(std::to_string(topo.degenerate_faces) + " degenerate proxy triangles");
  r.euler = topo.euler();
  r.triangles = mesh.faces.size();
  r.vertices = size_t(topo.vertices);

  Components comps = find_components(mesh);
  r.outer_components = 0;
  r.outward = comps.count > 0;
  for (int c = 0; c < comps.count; ++c) {
    if (!comps.inner[c]) ++r.outer_components;
    if (!(comps.volume[c] > 0)) r.outward = false;
  }
  r.genus = r.closed ? int((2L * comps.count - r.euler) / 2) : 0;
  r.proxy.face_component = comps.face_component;

  progress.update("proxy: checks", 0.2);
  geometry::DistanceBvh proxy_bvh(mesh);
  size_t outside = 0;
#pragma omp parallel for schedule(dynamic, 1024) reduction(+ : outside)
  for (long i = 0; i < long(soup_points.size()); ++i) outside += !proxy_bvh.contains(soup_points[i]);
  r.soup_vertices_outside = outside;
  r.encloses = outside == 0;

  progress.update("proxy: checks", 0.5);
  // Every vertex and every face centroid, once each. Queries answer exactly
  // below 2o (the proxy lies near d = o, so the minimum is far below that;
  // a minimum >= 2o would be reported as 2o) and start from the previous
  // query's closest triangle: both let the BVH prune from the start.
  const double cap = 2 * offset;
  double min_d = INFINITY;
#pragma omp parallel reduction(min : min_d)
  {
    uint32_t warm = UINT32_MAX;
#pragma omp for schedule(static)
    for (long v = 0; v < long(mesh.vertices.size()); ++v)
      min_d = std::min(min_d, soup_bvh.distance(mesh.vertices[size_t(v)], 0, cap, &warm));
#pragma omp for schedule(static)
    for (long f = 0; f < long(mesh.faces.size()); ++f) {
      const auto& t = mesh.faces[size_t(f)];
      Vec3 centroid = (mesh.vertices[t[0]] + mesh.vertices[t[1]] + mesh.vertices[t[2]]) / 3.0;
      min_d = std::min(min_d, soup_bvh.distance(centroid, 0, cap, &warm));
    }
  }
  r.min_distance = mesh.faces.empty() ? 0 : min_d;
  r.min_distance_ratio = r.min_distance / offset;

  progress.update("proxy: checks", 0.7);
  r.self_intersections_checked = false;
  r.self_intersections = false;
  if (check_self_intersections && r.manifold) {
    r.self_intersections = cgal::self_intersects(mesh);
    r.self_intersections_checked = true;
  }
}

bool acceptable(const ProxyResult& r) {
  return r.closed && r.manifold && r.outward && r.encloses && !r.self_intersections &&
         r.min_distance_ratio >= 0.5;
}

}  // namespace

nlohmann::json ProxyResult::diagnostics() const {
  return {
      {"closed", closed},
      {"manifold", manifold},
      {"outward", outward},
      {"euler", euler},
      {"genus", genus},
      {"outer_components", outer_components},
      {"inner_components", inner_components},
      {"encloses", encloses},
      {"soup_vertices_outside", soup_vertices_outside},
      {"min_distance", min_distance},
      {"min_distance_ratio", min_distance_ratio},
      {"self_intersections_checked", self_intersections_checked},
      {"self_intersections", self_intersections},
      {"triangles", triangles},
      {"vertices", vertices},
      {"raw_triangles", raw_triangles},
      {"collapsed_triangles", collapsed_triangles},
      {"estimated_triangles", estimated_triangles},
      {"surface_cells", surface_cells},
      {"pruned_cells", pruned_cells},
      {"distance_evaluations", distance_evaluations},
      {"offset", offset},
      {"offset_fraction", offset_fraction},
      {"resolution", resolution},
      {"cell_size", cell_size},
      {"ladder_tried", ladder_tried},
      {"seconds", seconds},
      {"seconds_grid", seconds_grid},
      {"seconds_extract", seconds_extract},
      {"seconds_remesh", seconds_remesh},
      {"seconds_decimate", seconds_decimate},
      {"seconds_smooth", seconds_smooth},
      {"seconds_checks", seconds_checks},
      {"warnings", warnings},
  };
}

ProxyResult build_proxy(const Soup& soup, const ProxyOptions& options, Progress& progress) {
  auto start = Clock::now();
  validate(soup, options);
  ThreadScope threads(options.threads);

  Box3 box;
  for (const Tri& t : soup.triangles)
    for (uint32_t v : t) box.add(soup.positions[v]);
  const double diagonal = box.diagonal();
  if (!(diagonal > 0)) throw Error(ErrorCode::invalid_input, "proxy: the soup spans no volume (a single point)");
  Vec3 ext = box.extent();
  const double longest = std::max({ext.x, ext.y, ext.z});
  geometry::DistanceBvh soup_bvh(soup);
  const std::vector<Vec3> soup_points = used_positions(soup);

  std::vector<double> offsets;  // absolute offsets to try, tightest first
  if (options.offset_mode == OffsetMode::automatic) {
    std::vector<double> ladder = options.ladder;
    std::sort(ladder.begin(), ladder.end());
    for (double f : ladder) offsets.push_back(f * diagonal);
  } else {
    offsets.push_back(absolute_offset(options.offset_mode, options.offset, diagonal));
  }

  std::optional<ProxyResult> best;
  int rungs_over_budget = 0;  // automatic rungs skipped for the face budget
  for (size_t rung = 0; rung < offsets.size(); ++rung) {
    const double offset = offsets[rung];
    const bool last = rung + 1 == offsets.size();
    // A rung the resolution cap cannot sample (cell > o/2) gives a level set
    // that may cut into the soup: automatic skips it.
    if (options.offset_mode == OffsetMode::automatic && options.resolution == 0 && !last &&
        nyquist_resolution(longest, offset) > options.max_resolution)
      continue;
    ProxyResult r;
    r.offset = offset;
    r.offset_fraction = offset / diagonal;
    r.resolution = sampling_resolution(options, longest, offset);
    if (options.offset_mode == OffsetMode::automatic) r.ladder_tried.push_back(r.offset_fraction);
    if (best) r.ladder_tried.insert(r.ladder_tried.begin(), best->ladder_tried.begin(), best->ladder_tried.end());
    if (r.resolution < nyquist_resolution(longest, offset))
      r.warnings.push_back("resolution " + std::to_string(r.resolution) +
                           " is below the sampling resolution " +
                           std::to_string(nyquist_resolution(longest, offset)) +
                           " for this offset: the level set may cut into the soup");

    const double target = options.target_edge_length > 0 ? options.target_edge_length : offset;
    Extraction ex = extract(soup_bvh, box, offset, r.resolution, options.marching_cubes, options.prune_cavities,
                            options.remesh ? target : 0.0, options.max_triangles, progress);
    if (ex.over_budget) {
      ++rungs_over_budget;
      // Automatic: a looser rung has less surface to tile; explicit: say so.
      if (options.offset_mode == OffsetMode::automatic && !last) continue;
      throw Error(ErrorCode::invalid_input,
                  "proxy: offset " + std::to_string(offset) + " with edge length " + std::to_string(target) +
                      " would make a proxy of about " + std::to_string(std::llround(ex.estimated_triangles)) +
                      " triangles, over its budget of " + std::to_string(options.max_triangles) +
                      " (the atlas's cost grows faster than its size); use a larger offset or "
                      "--proxy-edge, or raise --proxy-max-triangles");
    }
    r.cell_size = ex.cell;
    r.raw_triangles = ex.raw_triangles;
    r.estimated_triangles = ex.estimated_triangles;
    r.surface_cells = ex.surface_cells;
    r.pruned_cells = ex.pruned;
    r.distance_evaluations = ex.evaluations;
    r.inner_components = ex.inner;
    r.seconds_grid = ex.seconds_grid;
    r.seconds_extract = ex.seconds_extract;
    r.seconds_decimate = ex.seconds_decimate;
    r.collapsed_triangles = ex.collapsed_triangles;
    // The ladder wants one outer component; anything else: next rung.
    if (options.offset_mode == OffsetMode::automatic && ex.outer != 1 && !last) {
      best = std::move(r);
      continue;
    }

    TriMesh mesh = ex.mesh;
    auto t0 = Clock::now();
    // The collapse (part of the extraction) already brought the mesh near
    // the target; CGAL's isotropic remeshing evens it out.
    if (options.remesh && options.remesh_iterations > 0 && !mesh.faces.empty()) {
      progress.update("proxy: remeshing", 0);
      mesh = cgal::isotropic_remesh(mesh, target, options.remesh_iterations);
    }
    r.seconds_remesh = since(t0) + ex.seconds_decimate;
    t0 = Clock::now();
    progress.update("proxy: smoothing", 0);
    taubin_smooth(mesh, options.smoothing_iterations);
    if (options.lift_iterations > 0)
      lift_to_offset(mesh, soup_bvh, offset, 0.25 * target, options.lift_iterations);
    r.seconds_smooth = since(t0);

    t0 = Clock::now();
    measure(mesh, soup_bvh, soup_points, offset, options.check_self_intersections, progress, r);
    if (!acceptable(r) && (options.remesh || options.smoothing_iterations > 0)) {
      // CGAL remeshing and smoothing are improvements, not requirements: when
      // they broke a check, fall back to the (collapsed) level set and measure again.
      ProxyResult raw = r;
      raw.warnings.push_back("remeshed/smoothed proxy failed a check (closed " +
                             std::to_string(r.closed) + ", manifold " + std::to_string(r.manifold) +
                             ", encloses " + std::to_string(r.encloses) + ", self-intersections " +
                             std::to_string(r.self_intersections) + ", min distance ratio " +
                             std::to_string(r.min_distance_ratio) + "); kept the collapsed level set");
      mesh = ex.mesh;
      measure(mesh, soup_bvh, soup_points, offset, options.check_self_intersections, progress, raw);
      r = std::move(raw);
    }
    r.seconds_checks = since(t0);
    r.proxy.mesh = std::move(mesh);
    r.proxy.outer_components = r.outer_components;
    r.proxy.offset = offset;
    r.proxy.resolution = r.resolution;

    bool feasible = r.outer_components == 1 && acceptable(r);
    best = std::move(r);
    if (options.offset_mode != OffsetMode::automatic || feasible) break;
  }

  ProxyResult result = std::move(*best);
  if (rungs_over_budget > 0)
    result.warnings.push_back("automatic offset: " + std::to_string(rungs_over_budget) +
                              " tighter rung(s) skipped, their proxy over the budget of " +
                              std::to_string(options.max_triangles) + " triangles");
  if (options.offset_mode == OffsetMode::automatic && !(result.outer_components == 1 && acceptable(result)))
    result.warnings.push_back("automatic offset: no rung of the ladder gave one enclosing outer component");
  if (result.outer_components > 1)
    result.warnings.push_back(std::to_string(result.outer_components) +
                              " outer components: parts farther apart than twice the offset; each gets its own charts");
  if (!result.encloses)
    result.warnings.push_back(std::to_string(result.soup_vertices_outside) + " soup vertices outside the proxy");
  result.seconds = since(start);
  progress.update("proxy: done", 1);
  return result;
}

}  // namespace soupuv::proxy
