#include "atlas/merge_charts.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include "atlas/pack.h"
#include "atlas/parameterize.h"

namespace soupuv::atlas {
namespace {

struct Candidate {
  int a, b;          // chart indices, a < b
  double smooth;     // shared boundary length across smooth edges
};

}  // namespace

int merge_charts(const TriMesh& mesh, const MeshTopology& t, const std::vector<char>& seam,
                 std::vector<FlatChart>& charts, std::vector<int>& face_chart,
                 std::vector<int>& face_local, const MergeOptions& options) {
  const double cos_crease = std::cos(options.crease_deg * M_PI / 180.0);
  const int nf = static_cast<int>(face_chart.size());
  std::set<std::pair<int, int>> failed;  // chart ids
  double surface = 0;
  for (double a : t.face_area) surface += a;
  auto area_of = [&](const FlatChart& c) {
    double a = 0;
    for (int f : c.mesh.faces) a += t.face_area[f];
    return a;
  };
  int merges = 0;
  for (int round = 0; round < options.rounds; ++round) {
    const int n = static_cast<int>(charts.size());
    std::map<int, int> index_of;  // chart id -> index
    for (int i = 0; i < n; ++i) index_of[face_chart[charts[i].mesh.faces[0]]] = i;
    std::map<std::pair<int, int>, std::pair<double, double>> shared;  // (smooth, total)
    for (int f = 0; f < nf; ++f)
      for (int k = 0; k < 3; ++k) {
        const int g = t.face_neighbor[f][k];
        const int e = t.face_edge[f][k];
        if (f > g || face_chart[f] == face_chart[g] || seam[e]) continue;
        int a = index_of.at(face_chart[f]), b = index_of.at(face_chart[g]);
        if (a > b) std::swap(a, b);
        auto& s = shared[{a, b}];
        s.second += t.edge_length[e];
        if (dot(t.face_normal[f], t.face_normal[g]) >= cos_crease) s.first += t.edge_length[e];
      }
    std::vector<Candidate> candidates;
    for (const auto& [pair, len] : shared) {
      const int ida = face_chart[charts[pair.first].mesh.faces[0]];
      const int idb = face_chart[charts[pair.second].mesh.faces[0]];
      if (len.first > 0.5 * len.second && !failed.count({std::min(ida, idb), std::max(ida, idb)}) &&
          area_of(charts[pair.first]) + area_of(charts[pair.second]) <= options.max_area_fraction * surface)
        candidates.push_back({pair.first, pair.second, len.first});
    }
    std::stable_sort(candidates.begin(), candidates.end(),
                     [](const Candidate& x, const Candidate& y) { return x.smooth > y.smooth; });
    // A matching: each chart in at most one trial per round, so the trials
    // touch disjoint faces and run in parallel.
    std::vector<char> busy(n, 0);
    std::vector<Candidate> batch;
    for (const Candidate& c : candidates)
      if (!busy[c.a] && !busy[c.b]) {
        busy[c.a] = busy[c.b] = 1;
        batch.push_back(c);
      }
    if (batch.empty()) break;
    // Relabel first (face_chart is read by every extraction), then flatten.
    std::vector<int> id_a(batch.size()), id_b(batch.size());
    for (size_t i = 0; i < batch.size(); ++i) {
      id_a[i] = face_chart[charts[batch[i].a].mesh.faces[0]];
      id_b[i] = face_chart[charts[batch[i].b].mesh.faces[0]];
      for (int f : charts[batch[i].b].mesh.faces) face_chart[f] = id_a[i];
    }
    std::vector<FlatChart> merged(batch.size());
    std::vector<char> ok(batch.size(), 0);
#pragma omp parallel for schedule(dynamic, 1) num_threads(options.threads)
    for (int i = 0; i < static_cast<int>(batch.size()); ++i) {
      std::vector<int> faces = charts[batch[i].a].mesh.faces;
      const auto& more = charts[batch[i].b].mesh.faces;
      faces.insert(faces.end(), more.begin(), more.end());
      if (options.max_normal_deviation_deg > 0) {
        Vec3 mean{0, 0, 0};
        for (int f : faces) mean += t.face_area[f] * t.face_normal[f];
        mean = normalized(mean);
        const double cos_cone = std::cos(options.max_normal_deviation_deg * M_PI / 180.0);
        if (!(norm2(mean) > 0) || std::any_of(faces.begin(), faces.end(), [&](int f) {
              return t.face_area[f] > 0 && dot(t.face_normal[f], mean) < cos_cone;
            }))
          continue;
      }
      merged[i].mesh = extract_chart(mesh, t, faces, face_chart, seam, face_local);
      if (!merged[i].mesh.is_disk()) continue;
      ChartParameterization p = parameterize_chart(merged[i].mesh, options.arap_iterations, options.max_stretch,
                                                   options.stretch_sweeps);
      if (!p.ok) continue;
      if (options.min_fill > 0) {
        double uv_area = 0;
        for (const auto& tri : merged[i].mesh.tri)
          uv_area += 0.5 * std::fabs(cross(p.uv[tri[1]] - p.uv[tri[0]], p.uv[tri[2]] - p.uv[tri[0]]));
        const MinRectangle rect = min_area_rectangle(p.uv);
        if (uv_area < options.min_fill * rect.size.x * rect.size.y) continue;
      }
      merged[i].uv = std::move(p.uv);
      ok[i] = 1;
    }
    std::vector<char> dead(n, 0);
    int merged_now = 0;
    for (size_t i = 0; i < batch.size(); ++i) {
      if (!ok[i]) {
        for (int f : charts[batch[i].b].mesh.faces) face_chart[f] = id_b[i];
        failed.insert({std::min(id_a[i], id_b[i]), std::max(id_a[i], id_b[i])});
        continue;
      }
      charts[batch[i].a] = std::move(merged[i]);
      dead[batch[i].b] = 1;
      ++merged_now;
    }
    std::vector<FlatChart> kept;
    kept.reserve(n - merged_now);
    for (int i = 0; i < n; ++i)
      if (!dead[i]) kept.push_back(std::move(charts[i]));
    charts = std::move(kept);
    merges += merged_now;
  }
  return merges;
}

}  // namespace soupuv::atlas
