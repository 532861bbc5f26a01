// The triangle soup every stage shares: positions, triangles and, per triangle,
// where it came from in the source file so the writer can put it back.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "soupuv/vec.h"

namespace soupuv {

// Where a soup triangle came from. Indices refer to the source glTF document;
// a raw .drc file has node = -1 and mesh = primitive = 0.
struct TriangleOrigin {
  int32_t node = -1;       // glTF node that instanced the mesh (-1: none)
  int32_t mesh = 0;        // glTF mesh index
  int32_t primitive = 0;   // primitive index inside the mesh
  int32_t material = -1;   // glTF material index (-1: default material)
  uint32_t source_index = 0;  // triangle index inside that primitive
};

struct Soup {
  // World-space positions (node transforms applied). double so that float
  // inputs round-trip exactly: every float is representable.
  std::vector<Vec3> positions;
  std::vector<Tri> triangles;              // indices into positions
  std::vector<TriangleOrigin> origins;     // one per triangle
  std::vector<std::string> warnings;       // non-fatal findings while loading

  size_t triangle_count() const { return triangles.size(); }
  Vec3 corner(size_t tri, int k) const { return positions[triangles[tri][k]]; }
};

Box3 bounding_box(const Soup& soup);

// Area of triangle t (0 for degenerate).
double triangle_area(const Soup& soup, size_t t);

// Unit normal of triangle t by its winding ({0,0,0} for degenerate).
Vec3 triangle_normal(const Soup& soup, size_t t);

// Mean length of the triangles' edges (each triangle's three; 0 if none).
double mean_edge_length(const Soup& soup);

// |b - a| + |c - b| + |a - c|.
double triangle_perimeter(Vec3 a, Vec3 b, Vec3 c);

// 128-bit content hash of the geometry (positions as used by the triangles, in
// triangle order), as 32 hex digits. Independent of origins and of how the
// vertices are shared, so the same triangles give the same key for caches.
std::string geometry_hash(const Soup& soup);

// Statistics telling whether a mesh is a soup: how many corners share a vertex
// index with another triangle, and how many distinct positions there are.
struct SharingStats {
  size_t corners = 0;
  size_t distinct_vertex_indices = 0;
  size_t distinct_positions = 0;       // exact position equality
  double shared_index_fraction = 0;    // corners whose index another triangle uses too
  bool is_soup = false;                // no shared indices at all
};
SharingStats sharing_stats(const Soup& soup);

}  // namespace soupuv
