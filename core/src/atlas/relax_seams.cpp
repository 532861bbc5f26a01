#include "atlas/relax_seams.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <queue>

#include "atlas/max_flow.h"
#include "atlas/parameterize.h"

namespace soupuv::atlas {
namespace {

struct PairCost {
  int a, b;        // chart indices, a < b
  double cost;     // weighted shared boundary
};

// A relabelling under trial: the faces that changed chart and their old ids.
struct Trial {
  int a = -1, b = -1;        // chart indices
  int id_a = -1, id_b = -1;  // their chart ids in face_chart
  std::vector<std::pair<int, int>> moved;  // (face, previous chart id)
  FlatChart new_a, new_b;
  double area_a = 0, area_b = 0;  // 3D areas of the two charts before
  double stretch_before = 0;      // their joint L2 stretch before
  bool ok = false;
};

double chart_area(const MeshTopology& t, const FlatChart& c) {
  double a = 0;
  for (int f : c.mesh.faces) a += t.face_area[f];
  return a;
}

// L2 stretch is a root mean square over area, so two charts combine as one.
double joint_stretch(double area_a, double sa, double area_b, double sb) {
  return std::sqrt((area_a * sa * sa + area_b * sb * sb) / (area_a + area_b));
}

double weight_of(const std::vector<double>& w, int f) { return w.empty() ? 1.0 : w[f]; }

double edge_cost(const MeshTopology& t, const std::vector<double>& w, int f, int k) {
  return t.edge_length[t.face_edge[f][k]] * 0.5 * (weight_of(w, f) + weight_of(w, t.face_neighbor[f][k]));
}

// The minimum-cost A/B boundary inside the band; returns the faces whose chart
// would change (empty when nothing gains enough).
std::vector<std::pair<int, int>> cheapest_cut(const MeshTopology& t, const std::vector<char>& seam,
                                              const std::vector<int>& face_chart,
                                              const std::vector<double>& w, const FlatChart& ca,
                                              const FlatChart& cb, double shared_cost,
                                              const RelaxOptions& options, std::vector<double>& dist,
                                              std::vector<int>& node_of) {
  const int id_a = face_chart[ca.mesh.faces[0]], id_b = face_chart[cb.mesh.faces[0]];
  auto in_pair = [&](int f) { return face_chart[f] == id_a || face_chart[f] == id_b; };
  double area_a = 0, area_b = 0;
  for (int f : ca.mesh.faces) area_a += t.face_area[f];
  for (int f : cb.mesh.faces) area_b += t.face_area[f];
  const double reach = options.band_fraction * std::sqrt(std::min(area_a, area_b));

  // Dijkstra over centroids from the faces on the shared boundary.
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> queue;
  std::vector<int> band;
  for (const FlatChart* c : {&ca, &cb})
    for (int f : c->mesh.faces)
      for (int k = 0; k < 3; ++k) {
        const int g = t.face_neighbor[f][k];
        if (!seam[t.face_edge[f][k]] && in_pair(g) && face_chart[g] != face_chart[f] && dist[f] > 0) {
          dist[f] = 0;
          queue.push({0.0, f});
        }
      }
  while (!queue.empty()) {
    const auto [d, f] = queue.top();
    queue.pop();
    if (d > dist[f] || node_of[f] >= 0) continue;
    node_of[f] = static_cast<int>(band.size());
    band.push_back(f);
    for (int k = 0; k < 3; ++k) {
      const int g = t.face_neighbor[f][k];
      if (seam[t.face_edge[f][k]] || !in_pair(g)) continue;
      const double dg = d + norm(t.face_centroid[g] - t.face_centroid[f]);
      if (dg <= reach && dg < dist[g]) {
        dist[g] = dg;
        queue.push({dg, g});
      }
    }
  }

  const int m = static_cast<int>(band.size());
  const int source = m, sink = m + 1;
  FlowGraph graph(m + 2);
  bool source_used = false, sink_used = false;
  for (int f : band)
    for (int k = 0; k < 3; ++k) {
      const int g = t.face_neighbor[f][k];
      if (seam[t.face_edge[f][k]] || !in_pair(g)) continue;
      const double c = edge_cost(t, w, f, k);
      if (node_of[g] >= 0) {
        if (f < g) graph.add_edge(node_of[f], node_of[g], c);
      } else if (face_chart[g] == id_a) {
        graph.add_edge(node_of[f], source, c);
        source_used = true;
      } else {
        graph.add_edge(node_of[f], sink, c);
        sink_used = true;
      }
    }
  std::vector<std::pair<int, int>> moved;
  // A chart wholly inside the band has no core to hold it: the cut could
  // swallow it. Such pairs stay as they are.
  if (source_used && sink_used) {
    const MinCut cut = graph.min_cut(source, sink);
    if (cut.capacity < (1 - options.min_gain) * shared_cost)
      for (int i = 0; i < m; ++i) {
        const int f = band[i];
        const int want = cut.source_side[i] ? id_a : id_b;
        if (face_chart[f] != want) moved.push_back({f, face_chart[f]});
      }
  }
  for (int f : band) {
    dist[f] = INFINITY;
    node_of[f] = -1;
  }
  // Faces queued but beyond reach were never settled; reset them too.
  for (const FlatChart* c : {&ca, &cb})
    for (int f : c->mesh.faces) dist[f] = INFINITY;
  return moved;
}

}  // namespace

double weighted_seam_length(const MeshTopology& t, const std::vector<int>& face_chart,
                            const std::vector<double>& w) {
  double sum = 0;
  for (size_t f = 0; f < face_chart.size(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int g = t.face_neighbor[f][k];
      if (static_cast<int>(f) < g && face_chart[f] != face_chart[g]) sum += edge_cost(t, w, static_cast<int>(f), k);
    }
  return sum;
}

RelaxStats relax_seams(const TriMesh& mesh, const MeshTopology& t, const std::vector<char>& seam,
                       std::vector<FlatChart>& charts, std::vector<int>& face_chart,
                       std::vector<int>& face_local, const std::vector<double>& w,
                       const RelaxOptions& options) {
  RelaxStats stats;
  stats.cost_before = weighted_seam_length(t, face_chart, w);
  const int nf = static_cast<int>(face_chart.size());
  const int n = static_cast<int>(charts.size());
  std::vector<int> version(n, 0);
  std::map<std::pair<int, int>, std::pair<int, int>> tried;  // pair -> versions when tried
  // A pair whose relabelling failed to flatten is tried again with half the
  // band (a narrower band keeps the cut closer to the boundary that did
  // flatten), at most `narrowings` times.
  std::map<std::pair<int, int>, int> failures;
  std::vector<double> dist(nf, INFINITY);
  std::vector<int> node_of(nf, -1);
  for (int round = 0; round < options.rounds; ++round) {
    std::map<int, int> index_of;  // chart id -> index
    for (int i = 0; i < n; ++i) index_of[face_chart[charts[i].mesh.faces[0]]] = i;
    std::map<std::pair<int, int>, double> shared;
    for (int f = 0; f < nf; ++f)
      for (int k = 0; k < 3; ++k) {
        const int g = t.face_neighbor[f][k];
        if (f > g || face_chart[f] == face_chart[g] || seam[t.face_edge[f][k]]) continue;
        int a = index_of.at(face_chart[f]), b = index_of.at(face_chart[g]);
        if (a > b) std::swap(a, b);
        shared[{a, b}] += edge_cost(t, w, f, k);
      }
    std::vector<PairCost> pairs;
    for (const auto& [p, cost] : shared) {
      auto it = tried.find(p);
      if (it != tried.end() && it->second == std::make_pair(version[p.first], version[p.second])) continue;
      pairs.push_back({p.first, p.second, cost});
    }
    std::stable_sort(pairs.begin(), pairs.end(), [](const PairCost& x, const PairCost& y) { return x.cost > y.cost; });
    // A matching, so the trials touch disjoint charts; each cut is found
    // and applied serially (cheap), the flattening runs in parallel.
    std::vector<char> busy(n, 0);
    std::vector<Trial> trials;
    for (const PairCost& p : pairs) {
      if (busy[p.a] || busy[p.b]) continue;
      tried[{p.a, p.b}] = {version[p.a], version[p.b]};
      ++stats.pairs_tried;
      RelaxOptions narrowed = options;
      narrowed.band_fraction = std::ldexp(options.band_fraction, -failures[{p.a, p.b}]);
      auto moved = cheapest_cut(t, seam, face_chart, w, charts[p.a], charts[p.b], p.cost, narrowed, dist, node_of);
      if (moved.empty()) continue;
      busy[p.a] = busy[p.b] = 1;
      const int id_a = face_chart[charts[p.a].mesh.faces[0]];
      const int id_b = face_chart[charts[p.b].mesh.faces[0]];
      for (auto& [f, old] : moved) face_chart[f] = old == id_a ? id_b : id_a;
      Trial trial;
      trial.a = p.a;
      trial.b = p.b;
      trial.id_a = id_a;
      trial.id_b = id_b;
      trial.area_a = chart_area(t, charts[p.a]);
      trial.area_b = chart_area(t, charts[p.b]);
      trial.stretch_before =
          joint_stretch(trial.area_a, chart_stretch_l2(charts[p.a].mesh, charts[p.a].uv), trial.area_b,
                        chart_stretch_l2(charts[p.b].mesh, charts[p.b].uv));
      trial.moved = std::move(moved);
      trials.push_back(std::move(trial));
    }
    if (trials.empty()) break;
#pragma omp parallel for schedule(dynamic, 1) num_threads(options.threads)
    for (int i = 0; i < static_cast<int>(trials.size()); ++i) {
      Trial& tr = trials[i];
      std::vector<int> union_faces = charts[tr.a].mesh.faces;
      union_faces.insert(union_faces.end(), charts[tr.b].mesh.faces.begin(), charts[tr.b].mesh.faces.end());
      std::vector<int> fa, fb;
      for (int f : union_faces) (face_chart[f] == tr.id_a ? fa : fb).push_back(f);
      if (fa.empty() || fb.empty()) continue;
      bool ok = true;
      double stretch[2] = {0, 0};
      int side = 0;
      for (auto [faces, out] : {std::pair{&fa, &tr.new_a}, std::pair{&fb, &tr.new_b}}) {
        out->mesh = extract_chart(mesh, t, *faces, face_chart, seam, face_local);
        if (!out->mesh.is_disk()) { ok = false; break; }
        ChartParameterization p = parameterize_chart(out->mesh, options.arap_iterations, options.max_stretch);
        if (!p.ok) { ok = false; break; }
        stretch[side++] = p.stretch_l2;
        out->uv = std::move(p.uv);
      }
      tr.ok = ok && joint_stretch(chart_area(t, tr.new_a), stretch[0], chart_area(t, tr.new_b), stretch[1]) <=
                        tr.stretch_before + options.max_stretch_increase;
    }
    for (Trial& tr : trials) {
      if (!tr.ok) {
        for (auto& [f, old] : tr.moved) face_chart[f] = old;
        if (++failures[{tr.a, tr.b}] <= options.narrowings) tried.erase({tr.a, tr.b});
        continue;
      }
      failures.erase({tr.a, tr.b});
      stats.faces_moved += static_cast<int>(tr.moved.size());
      ++stats.pairs_relaxed;
      charts[tr.a] = std::move(tr.new_a);
      charts[tr.b] = std::move(tr.new_b);
      ++version[tr.a];
      ++version[tr.b];
    }
  }
  stats.cost_after = weighted_seam_length(t, face_chart, w);
  return stats;
}

}  // namespace soupuv::atlas
