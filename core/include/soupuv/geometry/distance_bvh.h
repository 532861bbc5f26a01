// DistanceBvh: a bounding volume hierarchy over triangles for distance and
// inside queries — the distance from a point to the nearest triangle (the
// proxy's offset field d(x), paper §5) and ray parity (is a point inside a
// closed mesh). Its sibling SurfaceHitBvh (surface_hit_bvh.h) answers where a
// segment first hits an indexed mesh and its closest surface point, for
// landing field lines: the two trees keep different data (corner copies and
// float candidate lists here, face ids into a mesh there) for their hot loops.
//
// Input:  triangles as corner positions (a soup or an indexed mesh).
// Output: queries in O(log n) expected time; build is O(n log n) (median split).
// The queries are const and may run from many threads at once.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "soupuv/mesh.h"
#include "soupuv/geometry/candidate_list.h"
#include "soupuv/soup.h"
#include "soupuv/vec.h"

namespace soupuv::geometry {

// What a ray from a point says about being inside a closed surface.
enum class RayParity { inside, outside, uncertain };

class DistanceBvh {
 public:
  explicit DistanceBvh(const Soup& soup);
  explicit DistanceBvh(const TriMesh& mesh);
  explicit DistanceBvh(std::vector<std::array<Vec3, 3>> triangles);

  size_t size() const { return tris_.size(); }
  Box3 bounds() const;
  // The triangles in the BVH's own order (ids of every query refer to it).
  const std::array<Vec3, 3>& triangle(uint32_t i) const { return tris_[i]; }

  // Distance from p to the nearest triangle, answered only as precisely as a
  // caller deciding "below lo / inside [lo, hi] / above hi" needs: the exact
  // distance when it lies in [lo, hi]; some value < lo (an upper bound of the
  // distance) as soon as one triangle closer than lo is found; hi when no
  // triangle is closer than hi. lo = 0, hi = INFINITY gives the exact distance.
  // `nearest` (optional, in/out) is a warm start: a triangle id (opaque, from
  // an earlier query nearby) tried before the traversal, so the search starts
  // with a tight bound and prunes more; on return it holds the closest
  // triangle found (unchanged when none is closer than hi).
  double distance(Vec3 p, double lo = 0, double hi = INFINITY, uint32_t* nearest = nullptr) const;

  // Fills `out` with every triangle whose bounding box lies within `radius`
  // of `box` (a superset of the triangles within `radius` of it).
  // With radius >= (distance from the box center to the soup) + half the box
  // diagonal, the list holds the closest triangle of every point of the box,
  // so distance_among over it is exact there (nearest-candidate culling).
  void gather(const Box3& box, double radius, CandidateList& out) const;

  // The same list for a `box` inside the box `from` was gathered for, with a
  // `radius` no larger than from's, picked out of `from` (a float scan of its
  // boxes) instead of a BVH descent: a parent's list serves its children.
  void narrow(const CandidateList& from, const Box3& box, double radius, CandidateList& out) const;

  // distance() restricted to the candidates of `list` (from gather), same
  // answer semantics; exact for points whose closest triangle is among them.
  double distance_among(Vec3 p, const CandidateList& list, double lo = 0, double hi = INFINITY,
                        uint32_t* nearest = nullptr) const;

  // Parity of the crossings of the ray p + t*dir, t > 0, with the triangles.
  // `uncertain` when the ray grazes an edge or vertex (try another direction).
  RayParity ray_parity(Vec3 p, Vec3 dir) const;

  // Inside test for a closed surface: ray parity along fixed skew directions,
  // the first that does not graze an edge decides (all grazing: outside).
  bool contains(Vec3 p) const;

 private:
  struct Node {
    Box3 box;
    uint32_t first = 0;  // leaf: first triangle; inner: index of the right child
    uint32_t count = 0;  // leaf: triangle count; inner: 0 (left child is next)
  };
  void build();
  void fill_boxes(CandidateList& out) const;
  uint32_t build_node(uint32_t first, uint32_t count, int depth);

  std::vector<std::array<Vec3, 3>> tris_;
  std::vector<Node> nodes_;
  std::vector<Box3> tri_boxes_;  // per triangle, in tris_ order (cheap lower bounds)
};

}  // namespace soupuv::geometry
