#include "pipeline/seam_weights.h"

#include <algorithm>
#include <cmath>

#include "soupuv/geometry/surface_hit_bvh.h"

namespace soupuv {

std::vector<double> soup_seam_weights(const Soup& soup, const TriMesh& proxy, int threads) {
  const size_t nf = proxy.faces.size();
  std::vector<double> weight(nf, 1.0);
  if (nf == 0 || soup.triangles.empty()) return weight;
  TriMesh soup_mesh;
  soup_mesh.vertices = soup.positions;
  soup_mesh.faces.reserve(soup.triangles.size());
  for (const Tri& t : soup.triangles)
    soup_mesh.faces.push_back({static_cast<int>(t[0]), static_cast<int>(t[1]), static_cast<int>(t[2])});
  const geometry::SurfaceHitBvh bvh(soup_mesh);

  std::vector<double> half_perimeter(soup.triangles.size()), area(soup.triangles.size());
  for (size_t i = 0; i < soup.triangles.size(); ++i) {
    const Vec3 a = soup.positions[soup.triangles[i][0]], b = soup.positions[soup.triangles[i][1]],
               c = soup.positions[soup.triangles[i][2]];
    half_perimeter[i] = 0.5 * (norm(b - a) + norm(c - b) + norm(a - c));
    area[i] = 0.5 * norm(cross(b - a, c - a));
  }
  double edge_sum = 0;
  size_t edges = 0;
  for (const auto& f : proxy.faces)
    for (int k = 0; k < 3; ++k, ++edges) edge_sum += norm(proxy.vertices[f[(k + 1) % 3]] - proxy.vertices[f[k]]);
  const double half = 0.5 * edge_sum / static_cast<double>(edges);

  std::vector<double> density(nf, 0), face_area(nf, 0);
#pragma omp parallel for schedule(dynamic, 256) num_threads(std::max(1, threads))
  for (long long f = 0; f < static_cast<long long>(nf); ++f) {
    const auto& tri = proxy.faces[f];
    const Vec3 a = proxy.vertices[tri[0]], b = proxy.vertices[tri[1]], c = proxy.vertices[tri[2]];
    face_area[f] = 0.5 * norm(cross(b - a, c - a));
    const geometry::SurfacePoint near = bvh.closest_point((a + b + c) / 3.0);
    if (!near.found()) continue;
    const Vec3 h{half, half, half};
    double perimeter_sum = 0, area_sum = 0;
    bvh.for_each_overlap(Box3{near.point - h, near.point + h}, [&](int t) {
      perimeter_sum += half_perimeter[t];
      area_sum += area[t];
    });
    // Only degenerate triangles nearby: the closest one alone, if it has area.
    if (!(area_sum > 0) && area[near.face] > 0) {
      perimeter_sum = half_perimeter[near.face];
      area_sum = area[near.face];
    }
    if (area_sum > 0) density[f] = perimeter_sum / area_sum;
  }
  double weighted = 0, total = 0;
  for (size_t f = 0; f < nf; ++f)
    if (density[f] > 0) {
      weighted += density[f] * face_area[f];
      total += face_area[f];
    }
  if (!(weighted > 0 && total > 0)) return weight;
  const double mean = weighted / total;
  for (size_t f = 0; f < nf; ++f)
    weight[f] = density[f] > 0 ? std::clamp(density[f] / mean, 0.05, 20.0) : 1.0;
  return weight;
}

}  // namespace soupuv
