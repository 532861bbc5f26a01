// Lift sunken proxy vertices along their normals. See
// soupuv/proxy/lift_to_offset.h.
#include "soupuv/proxy/lift_to_offset.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace soupuv::proxy {

double lift_to_offset(TriMesh& mesh, const geometry::DistanceBvh& soup_bvh, double offset, double max_step,
                      int iterations) {
  const long nv = long(mesh.vertices.size());
  std::vector<Vec3> normal(nv);
  std::vector<uint32_t> warm(nv, UINT32_MAX);
  double min_ratio = INFINITY;
  for (int it = 0; it <= iterations; ++it) {
    // Last round only measures.
    const bool move = it < iterations;
    std::fill(normal.begin(), normal.end(), Vec3{0, 0, 0});
    for (const auto& f : mesh.faces) {
      Vec3 n = cross(mesh.vertices[f[1]] - mesh.vertices[f[0]], mesh.vertices[f[2]] - mesh.vertices[f[0]]);
      for (int v : f) normal[v] += n;  // area weighted: |n| is twice the area
    }
    min_ratio = INFINITY;
#pragma omp parallel for schedule(dynamic, 512) reduction(min : min_ratio)
    for (long v = 0; v < nv; ++v) {
      double d = soup_bvh.distance(mesh.vertices[v], 0, offset, &warm[v]);
      double len = norm(normal[v]);
      if (move && d < offset && len > 0)
        mesh.vertices[v] += (std::min(offset - d, max_step) / len) * normal[v];
      min_ratio = std::min(min_ratio, d / offset);
    }
  }
  return min_ratio;
}

}  // namespace soupuv::proxy
