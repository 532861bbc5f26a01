#include "pipeline/shared_seeds.h"

#include <unordered_map>

namespace soupuv::pipeline {

SharedSeeds shared_seeds(const Soup& soup, const geometry::Weld& weld,
                         const field::Orientation& orientation) {
  SharedSeeds s;
  const size_t corners = 3 * soup.triangles.size();
  s.group_of_corner.assign(corners, UINT32_MAX);
  // A welded vertex touched by two orientation components (two parts meeting
  // at a point) gets one group per component: their sides are chosen apart.
  std::unordered_map<uint64_t, uint32_t> group_of_key;
  group_of_key.reserve(weld.vertex_count);
  std::vector<Vec3> position_sum, normal_sum, interior_sum;
  std::vector<uint32_t> count;
  std::vector<double> edge_sum;  // the group's triangles' edges
  for (size_t c = 0; c < corners; ++c) {
    const size_t t = c / 3;
    const uint64_t key = (uint64_t(orientation.component[t]) << 32) | weld.corner_vertex[c];
    auto [it, fresh] = group_of_key.try_emplace(key, uint32_t(count.size()));
    const uint32_t g = it->second;
    if (fresh) {
      position_sum.push_back({0, 0, 0});
      normal_sum.push_back({0, 0, 0});
      interior_sum.push_back({0, 0, 0});
      count.push_back(0);
      edge_sum.push_back(0);
      s.component.push_back(orientation.component[t]);
      s.area.push_back(0);
      field::TraceSeed seed;
      seed.corner = uint32_t(c);
      s.seeds.push_back(seed);
    }
    s.group_of_corner[c] = g;
    const double a = triangle_area(soup, t);
    position_sum[g] = position_sum[g] + soup.corner(t, c % 3);
    // Area-weighted: a sliver's normal is noise.
    normal_sum[g] = normal_sum[g] + (a * orientation.flip[t]) * triangle_normal(soup, t);
    interior_sum[g] = interior_sum[g] +
                      (soup.corner(t, 0) + soup.corner(t, 1) + soup.corner(t, 2)) / 3.0;
    s.area[g] += a;
    edge_sum[g] += triangle_perimeter(soup.corner(t, 0), soup.corner(t, 1), soup.corner(t, 2));
    ++count[g];
  }
  for (size_t g = 0; g < s.seeds.size(); ++g) {
    field::TraceSeed& seed = s.seeds[g];
    seed.position = position_sum[g] / double(count[g]);
    // A zero sum (a plate welded to its own back) leaves the tracer to fall
    // back on the first copy's triangle normal.
    seed.normal = norm2(normal_sum[g]) > 0 ? normalized(normal_sum[g])
                                           : triangle_normal(soup, seed.corner / 3);
    seed.interior = interior_sum[g] / double(count[g]);
    seed.has_interior = true;
    seed.scale = edge_sum[g] / (3.0 * count[g]);
    seed.side = 0;
  }
  return s;
}

int probed_line_side(const field::TraceSeed& seed, int probed) {
  // The line starts at position + probed * eps * normal: its first point off
  // the start lies on the probed side, unless the normal is zero.
  return norm2(seed.normal) > 0 ? probed : 0;
}

}  // namespace soupuv::pipeline
