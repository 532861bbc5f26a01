// Tri-planar box projection (see soupuv/baseline/box_projection.h).
#include "soupuv/baseline/box_projection.h"

#include <chrono>
#include <cmath>

#include "soupuv/errors.h"

namespace soupuv::baseline {

namespace {

// In-plane axes (a, b) per projection axis k, ordered so that e_a x e_b = +e_k:
// a triangle wound counter-clockwise seen from +k stays counter-clockwise in
// (a, b). The - faces swap them, which is the view from the other side.
constexpr int kAxisA[3] = {1, 2, 0};
constexpr int kAxisB[3] = {2, 0, 1};

}  // namespace

BoxResult box_projection(const Soup& soup, const BoxOptions& options, Progress& progress) {
  auto start = std::chrono::steady_clock::now();
  if (soup.triangles.empty()) throw Error(ErrorCode::no_triangles, "box projection: no triangles");
  if (!(options.padding >= 0 && options.padding < 1.0 / 6))
    throw Error(ErrorCode::invalid_input, "box projection: padding must be in [0, 1/6)");
  Box3 box = bounding_box(soup);
  Vec3 extent = box.extent();
  double scale = std::fmax(extent.x, std::fmax(extent.y, extent.z));
  if (!(scale > 0) || !std::isfinite(scale))
    throw Error(ErrorCode::invalid_input, "box projection: the soup has no extent");

  const double cell_w = 1.0 / 3, cell_h = 1.0 / 2;
  const double side = std::fmin(cell_w, cell_h) - 2 * options.padding;  // square image per face

  BoxResult result;
  result.corner_uvs.resize(soup.triangles.size() * 3);
  const size_t n = soup.triangles.size();
  for (size_t t = 0; t < n; ++t) {
    if ((t & 0xFFFF) == 0) progress.update("box", double(t) / n);
    Vec3 normal = triangle_normal(soup, t);
    int k = 0;
    for (int c = 1; c < 3; ++c)
      if (std::fabs(normal[c]) > std::fabs(normal[k])) k = c;
    bool negative = normal[k] < 0;
    result.face_triangles[k + (negative ? 3 : 0)]++;
    int a = negative ? kAxisB[k] : kAxisA[k];
    int b = negative ? kAxisA[k] : kAxisB[k];
    double cell_u = k * cell_w + options.padding;
    double cell_v = (negative ? 1 : 0) * cell_h + options.padding;
    for (int c = 0; c < 3; ++c) {
      Vec3 p = soup.corner(t, c);
      // Normalised to the bounding cube, in [0,1]; b flipped because glTF's v
      // runs down the image while our (a, b) frame has b up — so each face
      // image shows the soup upright and unmirrored, as seen from outside.
      double s = (p[a] - box.lo[a]) / scale;
      double r = 1.0 - (p[b] - box.lo[b]) / scale;
      result.corner_uvs[t * 3 + c] = {cell_u + s * side, cell_v + r * side};
    }
  }
  progress.update("box", 1.0);
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace soupuv::baseline
