// Where a field line starts (TraceOptions::start_offset and
// start_offset_fraction, TraceSeed::scale): one start offset off its seed
// along the normal, the offset a fraction of the seed's own edge length, so
// a small part of a soup starts as close to its surface, in its own edges,
// as a large one.
#include <gtest/gtest.h>

#include <cmath>

#include "soupuv/field/field.h"
#include "testing/shapes.h"

using namespace soupuv;
using namespace soupuv::field;

namespace {

// Two spheres of radius 1 and 0.1, far apart, as one soup.
Soup two_scales() {
  TriMesh big = shapes::icosphere(1.0, 2), small = shapes::icosphere(0.1, 2);
  for (Vec3& v : small.vertices) v = v + Vec3{4, 0, 0};
  TriMesh both = big;
  const uint32_t base = uint32_t(both.vertices.size());
  both.vertices.insert(both.vertices.end(), small.vertices.begin(), small.vertices.end());
  for (auto f : small.faces) both.faces.push_back({f[0] + base, f[1] + base, f[2] + base});
  return shapes::to_soup(both);
}

double distance_to_first_point(const FieldLines& lines, size_t i) {
  return norm(lines.points[lines.offsets[i] + 1] - lines.points[lines.offsets[i]]);
}

ChargeResult charged(const Soup& soup) {
  ChargeOptions co;
  co.tolerance = 1e-5;
  return solve_charges(soup, co);
}

}  // namespace

TEST(TraceStart, EachLineStartsAFractionOfItsSeedsEdgeOff) {
  const Soup soup = two_scales();
  const ChargeResult c = charged(soup);
  TraceOptions o;
  o.max_steps = 3;
  const std::vector<TraceSeed> seeds = corner_seeds(soup);
  const FieldLines lines = trace_field_lines(c, seeds, o);
  ASSERT_EQ(lines.size(), seeds.size());
  double small_scale = 0, big_scale = 0;
  for (size_t i = 0; i < seeds.size(); ++i) {
    const Vec3 a = soup.corner(seeds[i].corner / 3, 0), b = soup.corner(seeds[i].corner / 3, 1),
               cc = soup.corner(seeds[i].corner / 3, 2);
    const double edge = (norm(b - a) + norm(cc - b) + norm(a - cc)) / 3;
    ASSERT_NEAR(seeds[i].scale, edge, 1e-12 * edge) << "seed " << i;
    EXPECT_NEAR(distance_to_first_point(lines, i), o.start_offset_fraction * edge, 1e-9 * edge) << "line " << i;
    (seeds[i].position.x > 2 ? small_scale : big_scale) = edge;
  }
  // The small sphere's lines start ten times closer to it.
  EXPECT_NEAR(big_scale / small_scale, 10.0, 2.0);
}

TEST(TraceStart, AnAbsoluteStartOffsetHoldsForEverySeedAndNoScaleMeansTheMeanEdge) {
  const Soup soup = two_scales();
  const ChargeResult c = charged(soup);
  TraceOptions o;
  o.max_steps = 2;
  std::vector<TraceSeed> seeds = corner_seeds(soup);
  o.start_offset = 2e-3;
  FieldLines lines = trace_field_lines(c, seeds, o);
  for (size_t i = 0; i < seeds.size(); ++i)
    EXPECT_NEAR(distance_to_first_point(lines, i), 2e-3, 1e-12) << "line " << i;
  // Seeds without a scale take the mean edge of all source triangles.
  o.start_offset = 0;
  for (TraceSeed& s : seeds) s.scale = 0;
  lines = trace_field_lines(c, seeds, o);
  double edges = 0;
  for (const Tri& t : c.triangles)
    edges += norm(c.positions[t[1]] - c.positions[t[0]]) + norm(c.positions[t[2]] - c.positions[t[1]]) +
             norm(c.positions[t[0]] - c.positions[t[2]]);
  const double mean_edge = edges / (3.0 * c.triangles.size());
  for (size_t i = 0; i < seeds.size(); ++i)
    EXPECT_NEAR(distance_to_first_point(lines, i), o.start_offset_fraction * mean_edge, 1e-9 * mean_edge);
}

TEST(TraceStart, VertexSeedsTakeTheMeanEdgeOfTheirFaces) {
  const TriMesh mesh = shapes::icosphere(1.0, 1);
  const std::vector<TraceSeed> seeds = vertex_seeds(mesh);
  ASSERT_EQ(seeds.size(), mesh.vertices.size());
  for (const TraceSeed& s : seeds) {
    double sum = 0;
    int faces = 0;
    for (const auto& f : mesh.faces)
      for (int k = 0; k < 3; ++k)
        if (mesh.vertices[f[k]].x == s.position.x && mesh.vertices[f[k]].y == s.position.y &&
            mesh.vertices[f[k]].z == s.position.z) {
          const Vec3 a = mesh.vertices[f[0]], b = mesh.vertices[f[1]], c = mesh.vertices[f[2]];
          sum += (norm(b - a) + norm(c - b) + norm(a - c)) / 3;
          ++faces;
        }
    ASSERT_GT(faces, 0);
    EXPECT_NEAR(s.scale, sum / faces, 1e-12);
  }
}
