#include "soupuv/geometry/surface_hit_bvh.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "soupuv/geometry/closest_point.h"
#include "soupuv/geometry/segment_triangle.h"

namespace soupuv::geometry {

namespace {

constexpr uint32_t kLeafSize = 4;

// Slab test of the segment a + t d, t in [0, tmax], against a box.
bool segment_hits_box(const Box3& box, Vec3 a, Vec3 inv_d, double tmax) {
  double t0 = 0, t1 = tmax;
  for (int i = 0; i < 3; ++i) {
    double lo = (box.lo[i] - a[i]) * inv_d[i];
    double hi = (box.hi[i] - a[i]) * inv_d[i];
    if (lo > hi) std::swap(lo, hi);
    // NaN (0 * inf when the segment lies in a slab plane) keeps the interval.
    if (lo > t0) t0 = lo;
    if (hi < t1) t1 = hi;
    if (t0 > t1) return false;
  }
  return true;
}

double box_distance2(const Box3& box, Vec3 p) {
  double d2 = 0;
  for (int i = 0; i < 3; ++i) {
    double v = p[i] < box.lo[i] ? box.lo[i] - p[i] : (p[i] > box.hi[i] ? p[i] - box.hi[i] : 0);
    d2 += v * v;
  }
  return d2;
}

}  // namespace

SurfaceHitBvh::SurfaceHitBvh(const TriMesh& mesh) : mesh_(&mesh) {
  faces_.resize(mesh.faces.size());
  std::iota(faces_.begin(), faces_.end(), 0);
  build();
}

SurfaceHitBvh::SurfaceHitBvh(const TriMesh& mesh, std::vector<int> faces)
    : mesh_(&mesh), faces_(std::move(faces)) {
  build();
}

void SurfaceHitBvh::build() {
  nodes_.clear();
  if (faces_.empty()) return;
  std::vector<Vec3> centroids(mesh_->faces.size());
  for (int f : faces_) {
    const auto& tri = mesh_->faces[f];
    centroids[f] = (mesh_->vertices[tri[0]] + mesh_->vertices[tri[1]] + mesh_->vertices[tri[2]]) / 3.0;
  }
  nodes_.reserve(2 * faces_.size() / kLeafSize + 2);
  build_node(0, uint32_t(faces_.size()), centroids);
}

uint32_t SurfaceHitBvh::build_node(uint32_t first, uint32_t count, std::vector<Vec3>& centroids) {
  uint32_t id = uint32_t(nodes_.size());
  nodes_.push_back({});
  Box3 box, cbox;
  for (uint32_t i = first; i < first + count; ++i) {
    const auto& tri = mesh_->faces[faces_[i]];
    for (int k = 0; k < 3; ++k) box.add(mesh_->vertices[tri[k]]);
    cbox.add(centroids[faces_[i]]);
  }
  nodes_[id].box = box;
  if (count <= kLeafSize) {
    nodes_[id].first = first;
    nodes_[id].count = count;
    return id;
  }
  Vec3 ext = cbox.extent();
  int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
  uint32_t mid = first + count / 2;
  std::nth_element(faces_.begin() + first, faces_.begin() + mid, faces_.begin() + first + count,
                   [&](int a, int b) { return centroids[a][axis] < centroids[b][axis]; });
  uint32_t left = build_node(first, mid - first, centroids);
  uint32_t right = build_node(mid, first + count - mid, centroids);
  nodes_[id].left = left;
  nodes_[id].right = right;
  return id;
}

SurfacePoint SurfaceHitBvh::first_hit(Vec3 a, Vec3 b) const {
  SurfacePoint best;
  if (nodes_.empty()) return best;
  Vec3 d = b - a;
  Vec3 inv{1.0 / d.x, 1.0 / d.y, 1.0 / d.z};
  double tmax = 1.0;
  uint32_t stack[64];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& n = nodes_[stack[--top]];
    if (!segment_hits_box(n.box, a, inv, tmax)) continue;
    if (n.count > 0) {
      for (uint32_t i = n.first; i < n.first + n.count; ++i) {
        const auto& tri = mesh_->faces[faces_[i]];
        double t;
        std::array<double, 3> bary;
        if (geometry::segment_triangle_hit(a, b, mesh_->vertices[tri[0]], mesh_->vertices[tri[1]],
                             mesh_->vertices[tri[2]], t, bary) &&
            t <= tmax && (!best.found() || t < best.t)) {
          tmax = t;
          best.face = faces_[i];
          best.bary = bary;
          best.t = t;
        }
      }
    } else if (top + 2 <= 64) {
      stack[top++] = n.left;
      stack[top++] = n.right;
    }
  }
  if (best.found()) best.point = a + best.t * d;
  return best;
}

SurfacePoint SurfaceHitBvh::closest_point(Vec3 p) const {
  SurfacePoint best;
  if (nodes_.empty()) return best;
  double best_d2 = INFINITY;
  uint32_t stack[64];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& n = nodes_[stack[--top]];
    if (box_distance2(n.box, p) >= best_d2) continue;
    if (n.count > 0) {
      for (uint32_t i = n.first; i < n.first + n.count; ++i) {
        const auto& tri = mesh_->faces[faces_[i]];
        const geometry::ClosestPoint q = geometry::closest_point_on_triangle(
            p, mesh_->vertices[tri[0]], mesh_->vertices[tri[1]], mesh_->vertices[tri[2]]);
        double d2 = norm2(q.point - p);
        if (d2 < best_d2) {
          best_d2 = d2;
          best.face = faces_[i];
          best.bary = q.bary;
          best.point = q.point;
        }
      }
    } else if (top + 2 <= 64) {
      // Nearer child last so it is popped first: tighter bound sooner.
      double dl = box_distance2(nodes_[n.left].box, p), dr = box_distance2(nodes_[n.right].box, p);
      if (dl < dr) { stack[top++] = n.right; stack[top++] = n.left; }
      else { stack[top++] = n.left; stack[top++] = n.right; }
    }
  }
  best.t = std::sqrt(best_d2);
  return best;
}

}  // namespace soupuv::geometry
