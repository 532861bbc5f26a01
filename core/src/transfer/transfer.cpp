#include "soupuv/transfer/transfer.h"

#include <omp.h>

#include <atomic>
#include <chrono>

#include "soupuv/errors.h"
#include "soupuv/transfer/chart_fix.h"

namespace soupuv::transfer {

Vec2 atlas_uv(const atlas::Atlas& atlas, const geometry::SurfacePoint& p) {
  const auto& uv = atlas.face_uvs[p.face];
  return p.bary[0] * uv[0] + p.bary[1] * uv[1] + p.bary[2] * uv[2];
}

namespace {

enum class Landing { hit, ray, closest };

// First crossing of line i's polyline; else the ray along its last direction;
// else the proxy point closest to `fallback`.
geometry::SurfacePoint land_line(const geometry::SurfaceHitBvh& bvh, const field::FieldLines& lines, size_t i,
                       Vec3 fallback, double ray_length, Landing& how) {
  const uint32_t b = lines.offsets[i], e = lines.offsets[i + 1];
  geometry::SurfacePoint hit;
  for (uint32_t j = b; j + 1 < e && !hit.found(); ++j)
    hit = bvh.first_hit(lines.points[j], lines.points[j + 1]);
  how = Landing::hit;
  if (hit.found()) return hit;
  // A trapped line crawled along the soup: its last direction is tangent to
  // the surface, so a ray along it lands anywhere; the closest point is the
  // honest guess.
  const bool trapped = i < lines.ends.size() && lines.ends[i] == field::LineEnd::trapped;
  if (e - b >= 2 && !trapped) {
    Vec3 last = lines.points[e - 1];
    Vec3 dir = normalized(last - lines.points[e - 2]);
    hit = bvh.first_hit(last, last + ray_length * dir);
  }
  how = Landing::ray;
  if (hit.found()) return hit;
  how = Landing::closest;
  return bvh.closest_point(fallback);
}

double ray_length_for(const TriMesh& mesh) {
  Box3 box;
  for (const Vec3& v : mesh.vertices) box.add(v);
  return 4 * box.diagonal() + 1e-12;
}

}  // namespace

nlohmann::json TransferResult::diagnostics() const {
  return {{"lines", lines},
          {"hits", hits},
          {"hit_fraction", hit_fraction()},
          {"fallback", fallback_ray + fallback_closest},
          {"fallback_ray", fallback_ray},
          {"fallback_closest", fallback_closest},
          {"untraced_corners", untraced_corners},
          {"multi_chart_triangles", multi_chart_triangles},
          {"corrected_triangles", corrected_triangles},
          {"seconds", seconds}};
}

TransferResult transfer_uvs(const Soup& soup, const field::FieldLines& lines,
                            const proxy::ProxyMesh& proxy, const atlas::Atlas& atlas,
                            const TransferOptions& options, Progress& progress) {
  const size_t corners = soup.triangles.size() * 3;
  std::vector<uint32_t> line_of_corner(corners, UINT32_MAX);
  for (size_t i = 0; i < lines.size(); ++i) {
    if (lines.corner[i] >= corners)
      throw Error(ErrorCode::internal, "transfer: a field line names a corner the soup lacks");
    line_of_corner[lines.corner[i]] = uint32_t(i);
  }
  return transfer_uvs(soup, lines, line_of_corner, proxy, atlas, options, progress);
}

TransferResult transfer_uvs(const Soup& soup, const field::FieldLines& lines,
                            const std::vector<uint32_t>& line_of_corner,
                            const proxy::ProxyMesh& proxy, const atlas::Atlas& atlas,
                            const TransferOptions& options, Progress& progress) {
  auto t0 = std::chrono::steady_clock::now();
  const TriMesh& mesh = proxy.mesh;
  if (mesh.faces.empty()) throw Error(ErrorCode::internal, "transfer: the proxy has no faces");
  if (atlas.face_uvs.size() != mesh.faces.size() || atlas.face_chart.size() != mesh.faces.size())
    throw Error(ErrorCode::internal, "transfer: the atlas does not match the proxy");
  if (lines.offsets.size() != lines.size() + 1 || lines.corner.size() != lines.size())
    throw Error(ErrorCode::internal, "transfer: malformed field lines");
  const size_t corners = soup.triangles.size() * 3;
  if (line_of_corner.size() != corners)
    throw Error(ErrorCode::internal, "transfer: the corner-to-line map does not match the soup");
  for (size_t i = 0; i < lines.size(); ++i)
    if (lines.corner[i] >= corners)
      throw Error(ErrorCode::internal, "transfer: a field line names a corner the soup lacks");

  progress.update("transfer", 0);
  geometry::SurfaceHitBvh bvh(mesh);
  const double ray_length = ray_length_for(mesh);

  TransferResult r;
  r.lines = lines.size();
  std::vector<geometry::SurfacePoint> line_landing(lines.size());
  std::vector<uint8_t> line_missed(lines.size(), 0);
  std::atomic<size_t> hits{0}, ray{0}, closest{0}, done{0};

  const long long n = static_cast<long long>(lines.size());
  const int threads = options.threads > 0 ? options.threads : omp_get_max_threads();
  bool canceled = false;
#pragma omp parallel for schedule(dynamic, 256) num_threads(threads)
  for (long long i = 0; i < n; ++i) {
    if (canceled) continue;
    uint32_t c = lines.corner[i];
    Landing how;
    // The closest-point fallback starts from the line's own start, which is
    // the corner for per-corner lines and near every copy for shared ones.
    line_landing[i] = land_line(bvh, lines, size_t(i), soup.corner(c / 3, c % 3), ray_length, how);
    line_missed[i] = how != Landing::hit;
    if (how == Landing::hit) ++hits;
    else if (how == Landing::ray) ++ray;
    else ++closest;
    size_t d = ++done;
    if ((d & 4095) == 0 && omp_get_thread_num() == 0) {
      try {
        progress.update("transfer", 0.8 * double(d) / double(n));
      } catch (...) {
        canceled = true;  // cannot throw out of an OpenMP region
      }
    }
  }
  if (canceled) progress.check_canceled();

  r.landing.resize(corners);
  r.missed.assign(corners, 0);
  for (size_t c = 0; c < corners; ++c) {
    const uint32_t l = line_of_corner[c];
    if (l < lines.size()) {
      r.landing[c] = line_landing[l];
      r.missed[c] = line_missed[l];
      continue;
    }
    r.landing[c] = bvh.closest_point(soup.corner(c / 3, c % 3));
    r.missed[c] = 1;
    ++r.untraced_corners;
  }
  r.hits = hits;
  r.fallback_ray = ray;
  r.fallback_closest = closest + r.untraced_corners;
  r.first_chart.resize(corners);
  for (size_t c = 0; c < corners; ++c) r.first_chart[c] = atlas.face_chart[r.landing[c].face];

  r.corner_uvs.resize(soup.triangles.size());
  for (size_t c = 0; c < corners; ++c) r.corner_uvs[c / 3][c % 3] = atlas_uv(atlas, r.landing[c]);

  if (options.fix_chart_boundaries) {
    ChartFixResult fix = fix_chart_boundaries(soup, proxy, atlas, r.landing, r.corner_uvs, progress,
                                                 options.neighbours);
    r.multi_chart_triangles = fix.multi_chart_triangles;
    r.corrected_triangles = fix.corrected_triangles;
  } else {
    for (size_t t = 0; t < soup.triangles.size(); ++t) {
      int c0 = atlas.face_chart[r.landing[3 * t].face];
      r.multi_chart_triangles += c0 != atlas.face_chart[r.landing[3 * t + 1].face] ||
                                 c0 != atlas.face_chart[r.landing[3 * t + 2].face];
    }
  }
  progress.update("transfer", 1);
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

}  // namespace soupuv::transfer
