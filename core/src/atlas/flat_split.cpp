#include "atlas/flat_split.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "atlas/pack.h"

namespace soupuv::atlas {

namespace {
// Triangles (centroids and areas, in UV) on either side of the line across
// the long side of the minimal-area rectangle of `points` at the area
// median. -> 0 or 1 per triangle; empty when the area is 0. (The UV
// solve's halving for packing cuts where the fewest edges cross instead:
// uvsolve/halve_island.h.)
std::vector<int> area_median_sides(const std::vector<Vec2>& points, const std::vector<Vec2>& centroid,
                                   const std::vector<double>& area) {
  const int n = static_cast<int>(centroid.size());
  double total = 0;
  for (double a : area) total += a;
  if (!(total > 0)) return {};
  // Cut across the long side of the minimal-area rectangle: a square splits
  // into two rectangles, a long chart into two shorter ones.
  MinRectangle rect = min_area_rectangle(points);
  Vec2 axis = rect.size.x >= rect.size.y ? rect.axis : Vec2{-rect.axis.y, rect.axis.x};
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(),
            [&](int a, int b) { return dot(centroid[a], axis) < dot(centroid[b], axis); });
  std::vector<int> side(n, 1);
  double acc = 0;
  for (int i : order) {
    if (acc >= 0.5 * total) break;
    side[i] = 0;
    acc += area[i];
  }
  return side;
}
}  // namespace

std::optional<std::pair<FlatChart, FlatChart>> split_flat_chart(
    const FlatChart& chart, const TriMesh& mesh, const MeshTopology& topology,
    const std::vector<char>& seam, std::vector<int>& face_chart, int& next_id,
    std::vector<int>& face_local) {
  const int n = static_cast<int>(chart.mesh.faces.size());
  if (n < 2) return std::nullopt;
  std::vector<Vec2> centroid(n);
  std::vector<double> area(n);
  for (int i = 0; i < n; ++i) {
    const auto& t = chart.mesh.tri[i];
    Vec2 a = chart.uv[t[0]], b = chart.uv[t[1]], c = chart.uv[t[2]];
    centroid[i] = (a + b + c) * (1.0 / 3);
    area[i] = 0.5 * std::fabs(cross(b - a, c - a));
  }
  const std::vector<int> side = area_median_sides(chart.uv, centroid, area);
  if (side.empty()) return std::nullopt;

  const int old_id = face_chart[chart.mesh.faces[0]];
  std::vector<int> parent_index[2];
  std::vector<int> faces[2];
  for (int i = 0; i < n; ++i) {
    parent_index[side[i]].push_back(i);
    faces[side[i]].push_back(chart.mesh.faces[i]);
  }
  if (faces[0].empty() || faces[1].empty()) return std::nullopt;
  const int ids[2] = {next_id, next_id + 1};
  for (int h = 0; h < 2; ++h)
    for (int f : faces[h]) face_chart[f] = ids[h];
  FlatChart half[2];
  for (int h = 0; h < 2; ++h) {
    half[h].mesh = extract_chart(mesh, topology, faces[h], face_chart, seam, face_local);
    if (!half[h].mesh.is_disk()) {
      for (int f : chart.mesh.faces) face_chart[f] = old_id;
      return std::nullopt;
    }
    half[h].uv.resize(half[h].mesh.position.size());
    for (size_t j = 0; j < faces[h].size(); ++j)
      for (int k = 0; k < 3; ++k)
        half[h].uv[half[h].mesh.tri[j][k]] = chart.uv[chart.mesh.tri[parent_index[h][j]][k]];
  }
  next_id += 2;
  return std::make_pair(std::move(half[0]), std::move(half[1]));
}

}  // namespace soupuv::atlas
