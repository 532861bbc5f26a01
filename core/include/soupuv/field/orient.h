// Choosing the traced side of every soup triangle so neighbours agree
// (paper §12.4, which leaves one-sided soups open).
//
// A plate's field lines leave both faces with about the same strength, so the
// per-corner |E| rule of the tracer picks sides at random across the plate and
// a triangle's corners land on opposite sides of the proxy. We fix the side
// per welded component instead:
//   1. consistent_orientation: propagate one winding over the near-neighbour
//      graph (breadth first; a neighbour that traverses the shared edge in the
//      same direction is flipped), keeping the input winding of the larger
//      (area-weighted) part of each component;
//   2. component_sides: each traced corner votes, weighted by its triangle's
//      area, for the side its |E|-chosen line left on (relative to the
//      component's consistent winding); the majority is the component's side.
// Closed parts keep their outward side (|E| is near zero inside, the vote is
// clear); plates get one side for the whole plate.
//
// Input : soup, edge adjacency (geometry::edge_adjacency of a weld).
// Output: per triangle a flip (+1 keep winding, -1 reversed) and component id;
//         per component the traced side (+1 along the consistent normal).
#pragma once

#include <cstdint>
#include <vector>

#include "soupuv/field/field_lines.h"
#include "soupuv/geometry/weld.h"
#include "soupuv/soup.h"

namespace soupuv::field {

struct Orientation {
  std::vector<int8_t> flip;          // per triangle: +1 keep input winding, -1 reverse
  std::vector<uint32_t> component;   // per triangle
  uint32_t components = 0;
  size_t flipped_triangles = 0;      // triangles whose input winding was reversed
  size_t conflicting_edges = 0;      // non-orientable: neighbours disagree whatever we do
};

Orientation consistent_orientation(const Soup& soup,
                                   const std::vector<geometry::AdjacentPair>& adjacency);

// Side (+1 / -1) a field line left its corner on, relative to the triangle's
// input-winding normal: the sign of (p - corner) . normal for the first line
// point p off the triangle's plane; 0 when there is none.
int line_side(const Soup& soup, const field::FieldLines& lines, size_t line);

struct SideChoice {
  std::vector<int8_t> component_side;   // per component, relative to the consistent winding
  std::vector<int8_t> triangle_side;    // per triangle, relative to its input winding
  size_t mixed_triangles_before = 0;    // triangles whose corners' lines left on different sides
};

// Votes with the lines traced with the |E| rule (any subset of corners).
SideChoice component_sides(const Soup& soup, const Orientation& orientation,
                           const field::FieldLines& free_lines);

// Triangles whose traced corners left on different sides (lines by corner).
size_t mixed_side_triangles(const Soup& soup, const field::FieldLines& lines);

}  // namespace soupuv::field
