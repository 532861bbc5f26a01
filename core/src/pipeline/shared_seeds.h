// Shared field-line starts: the corners of a soup that weld to one position
// (the copies a soup made of one mesh vertex) start one common field line.
//
// Why: each copy of a split vertex sits at its own noisy position and would
// start at v + eps * n with its own triangle's normal; near creases and in
// concave regions those lines part ways and land far apart, which cuts the
// texture between triangles that were neighbours. One line per welded
// position gives every copy the same landing point (continuity by
// construction where the copies weld) and traces about six times fewer lines
// on a closed soup.
//
// Input : a soup, its weld (geometry::weld_corners) and a consistent
//         orientation (field::consistent_orientation) of the weld's graph.
// Output: one group per (welded vertex, orientation component); per group a
//         seed at the mean of its copies, along the area-weighted mean of their
//         consistently oriented normals (side 0: the tracer picks by |E|),
//         with the mean edge of their triangles as its scale (the tracer
//         starts the line a fraction of it off the surface), and the group
//         of every soup corner.
#pragma once

#include <cstdint>
#include <vector>

#include "soupuv/field/field.h"
#include "soupuv/geometry/weld.h"
#include "soupuv/soup.h"
#include "soupuv/field/orient.h"

namespace soupuv::pipeline {

struct SharedSeeds {
  // seeds[g].corner is a real soup corner of group g (its first copy), so the
  // traced lines still name the corner they start at.
  std::vector<field::TraceSeed> seeds;
  std::vector<uint32_t> group_of_corner;  // per soup corner (triangle * 3 + k)
  std::vector<uint32_t> component;        // per group: orientation component
  std::vector<double> area;               // per group: area of its triangles (vote weight)
};

SharedSeeds shared_seeds(const Soup& soup, const geometry::Weld& weld,
                         const field::Orientation& orientation);

// The side (+1 / -1 along seed.normal) a line traced from `seed` on its
// probed side (field::FieldLineTracer::probe_sides) leaves on: `probed`,
// or 0 when the seed has no normal (its side is then no vote).
int probed_line_side(const field::TraceSeed& seed, int probed);

}  // namespace soupuv::pipeline
