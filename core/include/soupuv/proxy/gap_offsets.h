// Gap-keeping offsets: a per-triangle offset that stays below half of the
// gap between parts of the soup that are close in space but far apart along
// the soup (two legs side by side, the ears, a tail lying on the body), so the
// offset surface does not fuse them.
//
// Input:  the soup's TriangleBvh (its triangles, in the BVH's own order),
//         the offset o, the smallest local offset o_min, the slit margin m
//         (half the width of the gap the level set must keep open), the weld
//         tolerance that tells which soup triangles touch (soups are split
//         and noisy: corners within it count as one vertex).
// Output: per triangle, in the BVH's order, the shift s_t = o - o_t with
//         o_t = clamp(gap_t / 2 - m, o_min, o), where gap_t is the distance
//         from t to the nearest triangle that is "far along the soup":
//         unreached by a walk over touching triangles within
//         kappa * 2o, or reached only along a path longer than
//         kappa * (their distance) + both triangles' radii. Set as the BVH's
//         shifts, the distance queries answer min_t (d(x, t) + s_t), which is
//         1-Lipschitz like d, and its level set at o is the union of balls
//         of radius o_t around the triangles.
// Why it keeps gaps: a point within o_t of t and within o_t' of a far t'
// would give d(t, t') < o_t + o_t' <= (gap_t + gap_t')/2 - 2m <= d(t, t') - 2m.
// So the shells of two far parts stay at least 2m apart; with m near the
// grid cell the level set sees the slit between them.
// Cost: per triangle, the k triangles within 2(o + m) in space (BVH gather,
// exact triangle distances, sorted) and a Dijkstra run lazily only as far as
// the nearest candidates need (it stops at the first far one, or when a near
// one is settled). k grows with the soup's density at a fixed offset
// fraction, so the whole is QUADRATIC in n: `soupuv-bench proxy --only=gaps`
// (two noisy spheres, offset 0.03, loaded machine): 0.31 s at 2,448
// triangles, 4.7 s at 9,520 (slope 2.0; the first, unlazy version took
// 0.59 / 9.8 / 555 s at 2.4k / 9.5k / 40k). Meant for the small coarse soups
// of the candidate search (Fox, 576 triangles: 0.10-0.26 s), not for big
// soups. When the offset is large against the soup, k nears n: the teapot
// with keep_gaps climbs the automatic ladder to 0.12 (its separate parts stay
// apart) and its proxy took 52 s (first version).
#pragma once

#include <vector>

#include "soupuv/proxy/triangle_bvh.h"

namespace soupuv::proxy {

struct GapOffsetOptions {
  double offset = 0;         // o
  double min_offset = 0;     // o_min (> 0): thinner shells than a grid cell are not sampled
  double margin = 0;         // m
  double weld_tolerance = 0; // corners closer than this touch
  double detour = 3;         // kappa: "far" = the walk is this many times longer than the gap
  int threads = 0;           // OpenMP threads; 0 = the caller's setting
};

struct GapOffsets {
  std::vector<double> shift;  // per BVH triangle: o - o_t, in [0, o - o_min]
  size_t narrowed = 0;        // triangles with o_t < o
  double smallest_offset = 0; // min o_t
};

GapOffsets gap_offsets(const TriangleBvh& bvh, const GapOffsetOptions& options);

// Distance between two triangles (0 only when they touch or cross is not
// promised: crossing triangles report their closest edge/corner distance).
double triangle_triangle_distance(const std::array<Vec3, 3>& a, const std::array<Vec3, 3>& b);

}  // namespace soupuv::proxy
