// SurfaceHitBvh: a bounding volume hierarchy over the triangles of a mesh
// (the proxy, or one chart of it, or a soup as a mesh): first hit of a segment
// or ray, the closest surface point (face and barycentrics: what the transfer
// needs to land a field line), and the faces whose boxes overlap a box. For
// distances and inside tests on a soup see DistanceBvh (distance_bvh.h).
//
// Input : mesh vertices and faces, optionally a subset of face ids.
// Output: queries returning the face id, barycentric coordinates and point.
// Cost  : build O(n log n) (median split on the longest axis of centroid
//         bounds); queries O(log n) typical.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "soupuv/mesh.h"
#include "soupuv/vec.h"

namespace soupuv::geometry {

struct SurfacePoint {
  int face = -1;                   // -1: nothing found
  std::array<double, 3> bary{};    // weights of the face's corners 0, 1, 2
  Vec3 point;
  double t = 0;                    // segment parameter (hits) or distance (closest)
  bool found() const { return face >= 0; }
};

class SurfaceHitBvh {
 public:
  SurfaceHitBvh() = default;
  // All faces of `mesh`; the mesh must outlive the BVH.
  explicit SurfaceHitBvh(const TriMesh& mesh);
  // Only `faces` (ids into mesh.faces).
  SurfaceHitBvh(const TriMesh& mesh, std::vector<int> faces);

  // First intersection of the segment a + t (b - a), t in [0, 1], with any
  // face, from either side. t of the result is the segment parameter.
  SurfacePoint first_hit(Vec3 a, Vec3 b) const;

  // Closest point of any face to p; t of the result is the distance.
  SurfacePoint closest_point(Vec3 p) const;

  // Calls f(face) for every face whose bounding box overlaps `box`.
  template <class F>
  void for_each_overlap(const Box3& box, F&& f) const {
    if (nodes_.empty()) return;
    uint32_t stack[64];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
      const Node& n = nodes_[stack[--top]];
      if (n.box.hi.x < box.lo.x || n.box.lo.x > box.hi.x || n.box.hi.y < box.lo.y ||
          n.box.lo.y > box.hi.y || n.box.hi.z < box.lo.z || n.box.lo.z > box.hi.z)
        continue;
      if (n.count > 0) {
        for (uint32_t i = n.first; i < n.first + n.count; ++i) f(faces_[i]);
      } else if (top + 2 <= 64) {
        stack[top++] = n.left;
        stack[top++] = n.right;
      }
    }
  }

  size_t size() const { return faces_.size(); }

 private:
  struct Node {
    Box3 box;
    uint32_t first = 0, count = 0;  // leaf: faces_[first .. first+count)
    uint32_t left = 0, right = 0;   // inner: child node ids (count == 0)
  };
  void build();
  uint32_t build_node(uint32_t first, uint32_t count, std::vector<Vec3>& centroids);

  const TriMesh* mesh_ = nullptr;
  std::vector<int> faces_;
  std::vector<Node> nodes_;
};

}  // namespace soupuv::geometry
