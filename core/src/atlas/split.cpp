#include "atlas/split.h"

#include <cmath>
#include <queue>
#include <unordered_map>

namespace soupuv::atlas {
namespace {

// Multi-source Dijkstra over the chart's faces; returns distance and source
// index per local face.
void grow(const MeshTopology& t, const std::vector<char>& seam, const std::vector<int>& faces,
          const std::vector<int>& face_chart, const std::unordered_map<int, int>& local,
          const std::vector<int>& sources, std::vector<double>& dist, std::vector<int>& owner) {
  const int chart = face_chart[faces[0]];
  dist.assign(faces.size(), INFINITY);
  owner.assign(faces.size(), -1);
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> queue;
  for (size_t s = 0; s < sources.size(); ++s) {
    dist[sources[s]] = 0;
    owner[sources[s]] = static_cast<int>(s);
    queue.push({0, sources[s]});
  }
  while (!queue.empty()) {
    auto [d, i] = queue.top();
    queue.pop();
    if (d > dist[i]) continue;
    int f = faces[i];
    for (int k = 0; k < 3; ++k) {
      int g = t.face_neighbor[f][k];
      if (face_chart[g] != chart || seam[t.face_edge[f][k]]) continue;
      int j = local.at(g);
      double nd = d + norm(t.face_centroid[g] - t.face_centroid[f]);
      if (nd < dist[j]) {
        dist[j] = nd;
        owner[j] = owner[i];
        queue.push({nd, j});
      }
    }
  }
}

int farthest(const std::vector<double>& dist) {
  int best = 0;
  for (size_t i = 0; i < dist.size(); ++i)
    if (std::isfinite(dist[i]) && dist[i] > dist[best]) best = static_cast<int>(i);
  return best;
}

}  // namespace

std::array<std::vector<int>, 2> split_chart(const MeshTopology& t, const std::vector<char>& seam,
                                            const std::vector<int>& faces,
                                            const std::vector<int>& face_chart) {
  std::array<std::vector<int>, 2> halves;
  if (faces.size() < 2) { halves[0] = faces; return halves; }
  std::unordered_map<int, int> local;
  local.reserve(faces.size() * 2);
  for (size_t i = 0; i < faces.size(); ++i) local[faces[i]] = static_cast<int>(i);
  std::vector<double> dist;
  std::vector<int> owner;
  grow(t, seam, faces, face_chart, local, {0}, dist, owner);
  int a = farthest(dist);
  grow(t, seam, faces, face_chart, local, {a}, dist, owner);
  int b = farthest(dist);
  if (b == a) b = (a + 1) % static_cast<int>(faces.size());
  grow(t, seam, faces, face_chart, local, {a, b}, dist, owner);
  for (size_t i = 0; i < faces.size(); ++i) halves[owner[i] == 1 ? 1 : 0].push_back(faces[i]);
  return halves;
}

}  // namespace soupuv::atlas
