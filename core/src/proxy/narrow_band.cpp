// Coarse-to-fine narrow band of f = d - o. See soupuv/proxy/narrow_band.h.
#include "soupuv/proxy/narrow_band.h"

#include <algorithm>
#include <cmath>

#include "soupuv/errors.h"

namespace soupuv::proxy {

double NarrowBand::value(uint64_t key) const {
  auto it = std::lower_bound(corner_keys.begin(), corner_keys.end(), key);
  if (it == corner_keys.end() || *it != key)
    throw Error(ErrorCode::internal, "narrow band: corner outside the band");
  return corner_values[it - corner_keys.begin()];
}

NarrowBand build_narrow_band(const TriangleBvh& bvh, const Box3& box, double offset,
                             double cell, Progress& progress) {
  NarrowBand band;
  band.offset = offset;
  band.cell = cell;
  double pad = offset + 2 * cell;
  band.origin = box.lo - Vec3{pad, pad, pad};
  Vec3 ext = box.extent() + Vec3{2 * pad, 2 * pad, 2 * pad};
  for (int a = 0; a < 3; ++a) {
    band.dims[a] = static_cast<int>(std::ceil(ext[a] / cell));
    if (band.dims[a] >= (1 << kGridBits) - 2)
      throw Error(ErrorCode::limit_exceeded, "proxy grid too fine for the offset");
  }
  // Top level: cells of 2^levels fine cells, about 8 along the longest axis.
  int longest = std::max({band.dims[0], band.dims[1], band.dims[2]});
  int levels = 0;
  while ((longest >> levels) > 8) ++levels;

  std::vector<uint64_t> current;
  int top = 1 << levels;
  for (int k = 0; k * top < band.dims[2]; ++k)
    for (int j = 0; j * top < band.dims[1]; ++j)
      for (int i = 0; i * top < band.dims[0]; ++i) current.push_back(grid_key(i, j, k));

  size_t evaluations = 0;
  // Refine down to cells of size 2h by the Lipschitz test on their centers;
  // their children are the candidate leaves, decided by their corners below.
  for (int level = levels; level >= 1; --level) {
    progress.update("proxy: narrow band", double(levels - level) / (levels + 1));
    double size = cell * (1 << level);
    double half_diagonal = 0.5 * std::sqrt(3.0) * size * (1 + 1e-9);
    std::vector<char> keep(current.size());
    // A cell can hold the level set only if |d(center) - o| <= half-diagonal.
#pragma omp parallel for schedule(dynamic, 256)
    for (long n = 0; n < long(current.size()); ++n) {
      auto c = grid_coords(current[n]);
      Vec3 center = band.origin + Vec3{(c[0] + 0.5) * size, (c[1] + 0.5) * size, (c[2] + 0.5) * size};
      // distance() answers exactly inside (lo, hi), below lo or == hi outside
      // it, so the test must be strict at both ends.
      double lo = offset - half_diagonal, hi = offset + half_diagonal;
      double d = bvh.distance(center, lo, hi);
      keep[n] = d > lo && d < hi;
    }
    evaluations += current.size();
    std::vector<uint64_t> next;
    for (size_t n = 0; n < current.size(); ++n) {
      if (!keep[n]) continue;
      auto c = grid_coords(current[n]);
      for (int dz = 0; dz < 2; ++dz)
        for (int dy = 0; dy < 2; ++dy)
          for (int dx = 0; dx < 2; ++dx) {
            int i = 2 * c[0] + dx, j = 2 * c[1] + dy, k = 2 * c[2] + dz;
            int child_size = 1 << (level - 1);
            if (i * child_size < band.dims[0] && j * child_size < band.dims[1] &&
                k * child_size < band.dims[2])
              next.push_back(grid_key(i, j, k));
          }
    }
    current.swap(next);
  }

  // Corners of the candidate leaves. Each lies within 2 sqrt(3) h of the level
  // set, so a band query of o +- 4h gives exact values wherever an edge
  // changes sign (1-Lipschitz); values outside the band only need their sign.
  band.corner_keys.reserve(current.size() * 3);
  for (uint64_t key : current) {
    auto c = grid_coords(key);
    for (int v = 0; v < 8; ++v)
      band.corner_keys.push_back(grid_key(c[0] + (v & 1), c[1] + ((v >> 1) & 1), c[2] + (v >> 2)));
  }
  std::sort(band.corner_keys.begin(), band.corner_keys.end());
  band.corner_keys.erase(std::unique(band.corner_keys.begin(), band.corner_keys.end()),
                         band.corner_keys.end());
  band.corner_values.resize(band.corner_keys.size());
  progress.update("proxy: narrow band", double(levels) / (levels + 1));
#pragma omp parallel for schedule(dynamic, 1024)
  for (long n = 0; n < long(band.corner_keys.size()); ++n) {
    double d = bvh.distance(band.corner_position(band.corner_keys[n]), offset - 4 * cell,
                            offset + 4 * cell);
    band.corner_values[n] = d - offset;
  }
  // Leaves: the candidates whose corners change sign; the others hold no
  // surface. Their unused corners stay (harmless, and lookups stay simple).
  std::vector<uint64_t> leaves;
  for (uint64_t key : current) {
    auto c = grid_coords(key);
    int inside = 0;
    for (int v = 0; v < 8; ++v)
      inside += band.value(grid_key(c[0] + (v & 1), c[1] + ((v >> 1) & 1), c[2] + (v >> 2))) < 0;
    if (inside != 0 && inside != 8) leaves.push_back(key);
  }
  std::sort(leaves.begin(), leaves.end());
  band.cells = std::move(leaves);
  band.distance_evaluations = evaluations + band.corner_keys.size();
  return band;
}

}  // namespace soupuv::proxy
