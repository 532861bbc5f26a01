// DistanceBvh: median-split BVH, point distance with a band early-out, ray
// parity. See soupuv/geometry/distance_bvh.h.
#include "soupuv/geometry/distance_bvh.h"

#include <algorithm>
#include <cmath>

#include "soupuv/geometry/closest_point.h"

namespace soupuv::geometry {
namespace {


constexpr uint32_t kLeafSize = 4;

// The hottest function of the proxy (a third of the narrow band's time):
// written per axis so it compiles to branch-free min/max.
double box_distance2(const Box3& box, Vec3 p) {
  double ex = std::max(std::max(box.lo.x - p.x, p.x - box.hi.x), 0.0);
  double ey = std::max(std::max(box.lo.y - p.y, p.y - box.hi.y), 0.0);
  double ez = std::max(std::max(box.lo.z - p.z, p.z - box.hi.z), 0.0);
  return ex * ex + ey * ey + ez * ez;
}

double box_box_distance2(const Box3& a, const Box3& b) {
  double ex = std::max(std::max(a.lo.x - b.hi.x, b.lo.x - a.hi.x), 0.0);
  double ey = std::max(std::max(a.lo.y - b.hi.y, b.lo.y - a.hi.y), 0.0);
  double ez = std::max(std::max(a.lo.z - b.hi.z, b.lo.z - a.hi.z), 0.0);
  return ex * ex + ey * ey + ez * ez;
}

// Slab test; true when the ray p + t*dir (t >= 0) meets the box.
bool ray_hits_box(const Box3& box, Vec3 p, Vec3 inv_dir) {
  // Per axis without Vec3::operator[] (a branch per access): this runs for
  // every node a ray visits.
  double ax = (box.lo.x - p.x) * inv_dir.x, bx = (box.hi.x - p.x) * inv_dir.x;
  double ay = (box.lo.y - p.y) * inv_dir.y, by = (box.hi.y - p.y) * inv_dir.y;
  double az = (box.lo.z - p.z) * inv_dir.z, bz = (box.hi.z - p.z) * inv_dir.z;
  double t0 = std::max({0.0, std::min(ax, bx), std::min(ay, by), std::min(az, bz)});
  double t1 = std::min({std::max(ax, bx), std::max(ay, by), std::max(az, bz)});
  return t0 <= t1;
}

// GCC/Clang vector extensions: four floats per operation on any x86-64
// (SSE2) without -march flags; the compiler does not vectorise the scalar
// form of the candidate scans by itself (max with NaN semantics).
typedef float Float4 __attribute__((vector_size(16)));
Float4 load4(const float* at) {
  Float4 v;
  __builtin_memcpy(&v, at, sizeof v);
  return v;
}
Float4 splat(float x) { return Float4{x, x, x, x}; }

// Fills entries [count, next multiple of kBlock) with padding: boxes 1e30
// away, whose lower bound overflows to +inf and never passes a test.
size_t padded_size(size_t count) {
  return (count + CandidateList::kBlock - 1) / CandidateList::kBlock * CandidateList::kBlock;
}
void pad(CandidateList& list, size_t count) {
  for (size_t n = count; n < padded_size(count); ++n) {
    list.ids[n] = UINT32_MAX;
    list.lo_x[n] = list.lo_y[n] = list.lo_z[n] = 1e30f;
    list.hi_x[n] = list.hi_y[n] = list.hi_z[n] = -1e30f;
    list.n_x[n] = list.n_y[n] = list.n_z[n] = list.w[n] = 0;
  }
}

// The caller's guess (`best`, e.g. the closest triangle of a neighbouring
// query) tightens the search radius before any traversal; a guess that is
// not closer than `best2` is dropped. True when it is already below lo2.
bool warm_start(const std::vector<std::array<Vec3, 3>>& tris, Vec3 p, double lo2, double& best2,
                uint32_t& best) {
  if (best >= tris.size()) return false;
  const auto& t = tris[best];
  double d2 = point_triangle_distance2(p, t[0], t[1], t[2]);
  if (d2 >= best2) {
    best = UINT32_MAX;
    return false;
  }
  best2 = d2;
  return best2 < lo2;
}

}  // namespace

DistanceBvh::DistanceBvh(const Soup& soup) {
  tris_.reserve(soup.triangles.size());
  for (const Tri& t : soup.triangles)
    tris_.push_back({soup.positions[t[0]], soup.positions[t[1]], soup.positions[t[2]]});
  build();
}

DistanceBvh::DistanceBvh(const TriMesh& mesh) {
  tris_.reserve(mesh.faces.size());
  for (const auto& f : mesh.faces)
    tris_.push_back({mesh.vertices[f[0]], mesh.vertices[f[1]], mesh.vertices[f[2]]});
  build();
}

DistanceBvh::DistanceBvh(std::vector<std::array<Vec3, 3>> triangles)
    : tris_(std::move(triangles)) {
  build();
}

Box3 DistanceBvh::bounds() const { return nodes_.empty() ? Box3{} : nodes_[0].box; }

void DistanceBvh::build() {
  nodes_.clear();
  if (tris_.empty()) return;
  nodes_.reserve(2 * tris_.size() / kLeafSize + 2);
  build_node(0, static_cast<uint32_t>(tris_.size()), 0);
  tri_boxes_.resize(tris_.size());
  for (size_t i = 0; i < tris_.size(); ++i)
    for (const Vec3& v : tris_[i]) tri_boxes_[i].add(v);
}

void DistanceBvh::gather(const Box3& box, double radius, CandidateList& out) const {
  out.clear(box.center());
  if (nodes_.empty()) return;
  double r2 = radius * radius;
  uint32_t stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& node = nodes_[stack[--top]];
    if (box_box_distance2(node.box, box) > r2) continue;
    if (node.count > 0) {
      for (uint32_t i = node.first; i < node.first + node.count; ++i)
        if (box_box_distance2(tri_boxes_[i], box) <= r2) out.ids.push_back(i);
      continue;
    }
    stack[top++] = node.first;
    stack[top++] = static_cast<uint32_t>(&node - nodes_.data()) + 1;
  }
  fill_boxes(out);
}

void DistanceBvh::fill_boxes(CandidateList& out) const {
  out.count = out.ids.size();
  out.ids.resize(padded_size(out.count));
  for (auto* v : out.arrays()) v->resize(padded_size(out.count));
  float extent = 0;
  for (size_t n = 0; n < out.count; ++n) {
    const Box3& b = tri_boxes_[out.ids[n]];
    Vec3 lo = b.lo - out.center, hi = b.hi - out.center;
    out.lo_x[n] = float(lo.x), out.lo_y[n] = float(lo.y), out.lo_z[n] = float(lo.z);
    out.hi_x[n] = float(hi.x), out.hi_y[n] = float(hi.y), out.hi_z[n] = float(hi.z);
    extent = std::max({extent, std::fabs(out.lo_x[n]), std::fabs(out.lo_y[n]), std::fabs(out.lo_z[n]),
                       std::fabs(out.hi_x[n]), std::fabs(out.hi_y[n]), std::fabs(out.hi_z[n])});
    const auto& t = tris_[out.ids[n]];
    Vec3 normal = cross(t[1] - t[0], t[2] - t[0]);
    double len = norm(normal);
    normal = len > 0 && std::isfinite(len) ? normal / len : Vec3{0, 0, 0};
    out.n_x[n] = float(normal.x), out.n_y[n] = float(normal.y), out.n_z[n] = float(normal.z);
    out.w[n] = float(dot(normal, t[0] - out.center));
  }
  pad(out, out.count);
  out.extent = extent;
}

void DistanceBvh::narrow(const CandidateList& from, const Box3& box, double radius, CandidateList& out) const {
  // Same local origin as `from`: the float boxes are copied, not re-rounded.
  out.clear(from.center);
  const Vec3 lo = box.lo - from.center, hi = box.hi - from.center;
  // Rounding slack as in distance_among: a candidate is dropped only when its
  // box is certainly farther than `radius` from `box`.
  const double scale = std::max({double(from.extent), std::fabs(lo.x), std::fabs(lo.y), std::fabs(lo.z),
                                 std::fabs(hi.x), std::fabs(hi.y), std::fabs(hi.z)});
  const double r = radius + scale * 0x1p-18;
  const float limit = float(r * r * (1 + 1e-6));
  const Float4 x0 = splat(float(lo.x)), y0 = splat(float(lo.y)), z0 = splat(float(lo.z));
  const Float4 x1 = splat(float(hi.x)), y1 = splat(float(hi.y)), z1 = splat(float(hi.z));
  auto axis = [](Float4 tri_lo, Float4 tri_hi, Float4 box_lo, Float4 box_hi) {
    Float4 below = tri_lo - box_hi, above = box_lo - tri_hi;
    Float4 e = below > above ? below : above;
    e = e > splat(0) ? e : splat(0);
    return e * e;
  };
  // Written in place (sized for all of `from`, cut to the kept count plus
  // padding at the end): no push_back in the loop.
  const size_t capacity = from.ids.size() + CandidateList::kBlock;
  out.ids.resize(capacity);
  for (auto* v : out.arrays()) v->resize(capacity);
  size_t kept = 0;
  float bound[CandidateList::kBlock];
  for (size_t s = 0; s < from.ids.size(); s += CandidateList::kBlock) {
    for (size_t k = 0; k < CandidateList::kBlock; k += 4) {
      Float4 b = axis(load4(&from.lo_x[s + k]), load4(&from.hi_x[s + k]), x0, x1) +
                 axis(load4(&from.lo_y[s + k]), load4(&from.hi_y[s + k]), y0, y1) +
                 axis(load4(&from.lo_z[s + k]), load4(&from.hi_z[s + k]), z0, z1);
      __builtin_memcpy(&bound[k], &b, sizeof b);
    }
    for (size_t k = 0; k < CandidateList::kBlock; ++k) {
      if (!(bound[k] <= limit)) continue;
      const size_t n = s + k;
      out.ids[kept] = from.ids[n];
      out.lo_x[kept] = from.lo_x[n], out.lo_y[kept] = from.lo_y[n], out.lo_z[kept] = from.lo_z[n];
      out.hi_x[kept] = from.hi_x[n], out.hi_y[kept] = from.hi_y[n], out.hi_z[kept] = from.hi_z[n];
      out.n_x[kept] = from.n_x[n], out.n_y[kept] = from.n_y[n], out.n_z[kept] = from.n_z[n];
      out.w[kept] = from.w[n];
      ++kept;
    }
  }
  out.count = kept;
  out.extent = from.extent;
  pad(out, kept);
  out.ids.resize(padded_size(kept));
  for (auto* v : out.arrays()) v->resize(padded_size(kept));
}

namespace {

// The running search both distance queries share: the squared distance to
// beat (hi^2 to start; INFINITY stays INFINITY), the squared early-stop bound
// (lo <= 0: never stop early), the nearest triangle so far (the caller's
// hint to start with) and its report to the caller.
struct NearestSearch {
  double best2, lo2;
  uint32_t best;
  uint32_t* nearest;
  size_t triangles;
  NearestSearch(double lo, double hi, uint32_t* nearest_out, size_t triangle_count)
      : best2(hi * hi), lo2(lo > 0 ? lo * lo : -1.0), best(nearest_out ? *nearest_out : UINT32_MAX),
        nearest(nearest_out), triangles(triangle_count) {}
  // Triangle i at squared distance d2: kept when nearer; true when the
  // search may stop (nearer than lo).
  bool offer(double d2, uint32_t i) {
    if (!(d2 < best2)) return false;
    best2 = d2;
    best = i;
    return best2 < lo2;
  }
  double done(double result) const {
    if (nearest && best < triangles) *nearest = best;
    return result;
  }
};

}  // namespace

double DistanceBvh::distance_among(Vec3 p, const CandidateList& list, double lo, double hi,
                                   uint32_t* nearest) const {
  NearestSearch search(lo, hi, nearest, tris_.size());
  if (warm_start(tris_, p, search.lo2, search.best2, search.best)) return search.done(std::sqrt(search.best2));
  const float px = float(p.x - list.center.x), py = float(p.y - list.center.y), pz = float(p.z - list.center.z);
  // Float rounding of a box or plane distance is below 2^-21 of the largest
  // local coordinate involved; 2^-18 of it as slack keeps every skip certain.
  const double slack = std::max({double(list.extent), std::fabs(double(px)), std::fabs(double(py)),
                                 std::fabs(double(pz))}) * 0x1p-18;
  auto threshold = [&] {
    if (!(search.best2 < INFINITY)) return double(INFINITY);
    double b = std::sqrt(search.best2) + slack;
    return b * b * (1 + 1e-6);
  };
  float limit = float(threshold());
  auto axis = [](Float4 lo, Float4 hi, Float4 q) {
    Float4 below = lo - q, above = q - hi;
    Float4 e = below > above ? below : above;
    e = e > splat(0) ? e : splat(0);
    return e * e;
  };
  const Float4 qx = splat(px), qy = splat(py), qz = splat(pz);
  float bound[CandidateList::kBlock];
  for (size_t s = 0; s < list.ids.size(); s += CandidateList::kBlock) {
    // Lower bounds for a block, then the rare candidates that could be
    // closer get the exact test.
    for (size_t k = 0; k < CandidateList::kBlock; k += 4) {
      Float4 b = axis(load4(&list.lo_x[s + k]), load4(&list.hi_x[s + k]), qx) +
                 axis(load4(&list.lo_y[s + k]), load4(&list.hi_y[s + k]), qy) +
                 axis(load4(&list.lo_z[s + k]), load4(&list.hi_z[s + k]), qz);
      Float4 plane = load4(&list.n_x[s + k]) * qx + load4(&list.n_y[s + k]) * qy +
                     load4(&list.n_z[s + k]) * qz - load4(&list.w[s + k]);
      plane = plane * plane;
      b = b > plane ? b : plane;
      __builtin_memcpy(&bound[k], &b, sizeof b);
    }
    for (size_t k = 0; k < CandidateList::kBlock; ++k) {
      if (!(bound[k] < limit)) continue;
      uint32_t i = list.ids[s + k];
      const auto& t = tris_[i];
      double d2 = point_triangle_distance2(p, t[0], t[1], t[2]);
      if (d2 < search.best2) {
        if (search.offer(d2, i)) return search.done(std::sqrt(search.best2));
        limit = float(threshold());
      }
    }
  }
  return search.done(search.best2 < hi * hi ? std::sqrt(search.best2) : hi);
}

uint32_t DistanceBvh::build_node(uint32_t first, uint32_t count, int depth) {
  uint32_t index = static_cast<uint32_t>(nodes_.size());
  nodes_.push_back({});
  Box3 box, centroids;
  for (uint32_t i = first; i < first + count; ++i) {
    for (const Vec3& v : tris_[i]) box.add(v);
    centroids.add((tris_[i][0] + tris_[i][1] + tris_[i][2]) / 3.0);
  }
  nodes_[index].box = box;
  Vec3 ext = centroids.extent();
  int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
  if (count <= kLeafSize || ext[axis] <= 0 || depth > 60) {
    nodes_[index].first = first;
    nodes_[index].count = count;
    return index;
  }
  uint32_t half = count / 2;
  auto centroid_along = [axis](const std::array<Vec3, 3>& t) {
    return t[0][axis] + t[1][axis] + t[2][axis];
  };
  std::nth_element(tris_.begin() + first, tris_.begin() + first + half,
                   tris_.begin() + first + count,
                   [&](const auto& a, const auto& b) { return centroid_along(a) < centroid_along(b); });
  build_node(first, half, depth + 1);
  uint32_t right = build_node(first + half, count - half, depth + 1);
  nodes_[index].first = right;
  nodes_[index].count = 0;
  return index;
}

double DistanceBvh::distance(Vec3 p, double lo, double hi, uint32_t* nearest) const {
  if (nodes_.empty()) return hi;
  NearestSearch search(lo, hi, nearest, tris_.size());
  if (warm_start(tris_, p, search.lo2, search.best2, search.best)) return search.done(std::sqrt(search.best2));
  uint32_t stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& node = nodes_[stack[--top]];
    if (box_distance2(node.box, p) >= search.best2) continue;
    if (node.count > 0) {
      for (uint32_t i = node.first; i < node.first + node.count; ++i) {
        const auto& t = tris_[i];
        double d2 = point_triangle_distance2(p, t[0], t[1], t[2]);
        if (search.offer(d2, i)) return search.done(std::sqrt(search.best2));
      }
      continue;
    }
    // Visit the nearer child first: it tightens the bound and prunes the other.
    uint32_t left = static_cast<uint32_t>(&node - nodes_.data()) + 1, right = node.first;
    double dl = box_distance2(nodes_[left].box, p), dr = box_distance2(nodes_[right].box, p);
    if (dl < dr) {
      if (dr < search.best2) stack[top++] = right;
      if (dl < search.best2) stack[top++] = left;
    } else {
      if (dl < search.best2) stack[top++] = left;
      if (dr < search.best2) stack[top++] = right;
    }
  }
  return search.done(search.best2 < hi * hi ? std::sqrt(search.best2) : hi);
}

RayParity DistanceBvh::ray_parity(Vec3 p, Vec3 dir) const {
  if (nodes_.empty()) return RayParity::outside;
  Vec3 inv{1.0 / dir.x, 1.0 / dir.y, 1.0 / dir.z};
  const double eps = 1e-9, dir2 = norm2(dir);
  int crossings = 0;
  uint32_t stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& node = nodes_[stack[--top]];
    if (!ray_hits_box(node.box, p, inv)) continue;
    if (node.count == 0) {
      stack[top++] = static_cast<uint32_t>(&node - nodes_.data()) + 1;
      stack[top++] = node.first;
      continue;
    }
    for (uint32_t i = node.first; i < node.first + node.count; ++i) {
      const auto& t = tris_[i];
      // Moller-Trumbore with a relative tolerance on the barycentrics: a hit
      // that close to an edge might be counted twice or not at all.
      Vec3 e1 = t[1] - t[0], e2 = t[2] - t[0];
      Vec3 pv = cross(dir, e2);
      double det = dot(e1, pv);
      // |det| <= 1e-12 |e1| |e2| |dir|, squared: no square roots for the
      // many triangles rejected below.
      double l1 = norm2(e1), l2 = norm2(e2);
      if (det * det <= 1e-24 * l1 * l2 * dir2) continue;  // parallel to the plane
      double inv_det = 1.0 / det;
      Vec3 tv = p - t[0];
      double u = dot(tv, pv) * inv_det;
      if (u < -eps || u > 1 + eps) continue;
      Vec3 qv = cross(tv, e1);
      double v = dot(dir, qv) * inv_det;
      if (v < -eps || u + v > 1 + eps) continue;
      double s = dot(e2, qv) * inv_det;
      double size = std::sqrt(std::max(l1, l2) / dir2);
      if (s < -eps * size) continue;
      if (s <= eps * size || u <= eps || v <= eps || u + v >= 1 - eps) return RayParity::uncertain;
      ++crossings;
    }
  }
  return crossings % 2 ? RayParity::inside : RayParity::outside;
}

bool DistanceBvh::contains(Vec3 p) const {
  static const Vec3 dirs[] = {{0.5773, 0.6123, 0.5401}, {-0.7071, 0.3117, -0.6347},
                              {0.1331, -0.9123, 0.3873}, {-0.4409, -0.5407, 0.7166},
                              {0.8791, -0.2213, -0.4222}};
  // The first direction that does not graze an edge decides; a point on the
  // surface itself grazes every direction and counts as outside.
  for (const Vec3& d : dirs) {
    RayParity r = ray_parity(p, d);
    if (r != RayParity::uncertain) return r == RayParity::inside;
  }
  return false;
}

}  // namespace soupuv::geometry
