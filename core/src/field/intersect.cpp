#include "soupuv/field/intersect.h"

#include <algorithm>
#include <cmath>

#include "soupuv/geometry/plane.h"
#include "soupuv/geometry/triangle_triangle.h"
#include "soupuv/geometry/surface_hit_bvh.h"

namespace soupuv::field {

namespace {

using Tri3 = std::array<Vec3, 3>;
using geometry::Plane;
using geometry::plane_of;
using Polygon = std::vector<Vec3>;

double polygon_area(const Polygon& p) {
  Vec3 s{};
  for (size_t i = 1; i + 1 < p.size(); ++i) s += cross(p[i] - p[0], p[i + 1] - p[0]);
  return 0.5 * norm(s);
}

// Sutherland-Hodgman: the part of a convex polygon with plane.at(x) >= 0 (keep
// = +1) or <= 0 (keep = -1).
Polygon clip(const Polygon& poly, const Plane& plane, int keep) {
  Polygon out;
  for (size_t i = 0; i < poly.size(); ++i) {
    Vec3 a = poly[i], b = poly[(i + 1) % poly.size()];
    double da = keep * plane.at(a), db = keep * plane.at(b);
    if (da >= 0) out.push_back(a);
    if ((da > 0 && db < 0) || (da < 0 && db > 0)) out.push_back(a + (b - a) * (da / (da - db)));
  }
  return out;
}

}  // namespace

nlohmann::json IntersectionRefinement::diagnostics() const {
  return {{"intersecting_pairs", intersecting_pairs},
          {"cut_triangles", cut_triangles},
          {"refined_triangles", soup.triangles.size()}};
}

IntersectionRefinement refine_intersections(const Soup& soup, Progress& progress, double min_depth) {
  constexpr size_t kMaxCutters = 8;  // bounds the pieces of one triangle
  const size_t n = soup.triangles.size();
  if (!(min_depth > 0)) min_depth = 5e-3 * bounding_box(soup).diagonal();
  auto tri = [&](size_t t) { return Tri3{soup.corner(t, 0), soup.corner(t, 1), soup.corner(t, 2)}; };

  TriMesh mesh;
  mesh.vertices.reserve(3 * n);
  for (size_t t = 0; t < n; ++t) {
    for (int k = 0; k < 3; ++k) mesh.vertices.push_back(soup.corner(t, k));
    mesh.faces.push_back({int(3 * t), int(3 * t + 1), int(3 * t + 2)});
  }
  geometry::SurfaceHitBvh bvh(mesh);

  // Cutters of each triangle: the planes that pass deeply through it.
  std::vector<std::vector<uint32_t>> cutters(n);
  IntersectionRefinement r;
  for (size_t a = 0; a < n; ++a) {
    if ((a & 4095) == 0) progress.update("intersections", 0.8 * double(a) / double(n));
    Tri3 ta = tri(a);
    Box3 box;
    for (Vec3 p : ta) box.add(p);
    bvh.for_each_overlap(box, [&](int bi) {
      size_t b = size_t(bi);
      if (b <= a) return;
      Tri3 tb = tri(b);
      auto deep = [&](const Tri3& cut, const Tri3& by) {
        Plane p = plane_of(by);
        double lo = INFINITY, hi = -INFINITY;
        for (Vec3 x : cut) { double d = p.at(x); lo = std::min(lo, d); hi = std::max(hi, d); }
        return lo < -min_depth && hi > min_depth;
      };
      bool a_cut = deep(ta, tb), b_cut = deep(tb, ta);
      if (!(a_cut || b_cut) || !geometry::triangles_intersect(ta, tb)) return;
      ++r.intersecting_pairs;
      if (a_cut && cutters[a].size() < kMaxCutters) cutters[a].push_back(uint32_t(b));
      if (b_cut && cutters[b].size() < kMaxCutters) cutters[b].push_back(uint32_t(a));
    });
  }

  r.soup.origins.reserve(n);
  r.soup.warnings = soup.warnings;
  for (size_t t = 0; t < n; ++t) {
    Tri3 ta = tri(t);
    const double min_area = 1e-10 * norm2(ta[1] - ta[0]) + 1e-300;
    auto emit = [&](Vec3 p0, Vec3 p1, Vec3 p2) {
      // Clipping leaves slivers where a corner lies (almost) on a cutting
      // plane; a zero-area source triangle has no charge density.
      if (cutters[t].size() && 0.5 * norm(cross(p1 - p0, p2 - p0)) <= min_area) return;
      uint32_t base = uint32_t(r.soup.positions.size());
      r.soup.positions.insert(r.soup.positions.end(), {p0, p1, p2});
      r.soup.triangles.push_back({base, base + 1, base + 2});
      r.soup.origins.push_back(soup.origins.empty() ? TriangleOrigin{} : soup.origins[t]);
      r.parent.push_back(uint32_t(t));
    };
    if (cutters[t].empty()) {
      emit(ta[0], ta[1], ta[2]);
      continue;
    }
    ++r.cut_triangles;
    // Split by each cutter's plane in turn: both sides of every piece.
    std::vector<Polygon> pieces{Polygon(ta.begin(), ta.end())};
    for (uint32_t c : cutters[t]) {
      const Plane p = plane_of(tri(c));
      std::vector<Polygon> next;
      for (const Polygon& piece : pieces)
        for (int keep : {1, -1}) {
          Polygon part = clip(piece, p, keep);
          if (part.size() >= 3 && polygon_area(part) > 0) next.push_back(std::move(part));
        }
      pieces = std::move(next);
    }
    for (const Polygon& piece : pieces)
      for (size_t i = 1; i + 1 < piece.size(); ++i) emit(piece[0], piece[i], piece[i + 1]);
  }
  progress.update("intersections", 1);
  return r;
}

}  // namespace soupuv::field
