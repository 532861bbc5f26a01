#include "atlas/segment.h"

#include <algorithm>
#include <cmath>
#include <queue>

namespace soupuv::atlas {
namespace {

// What a chart is fitted to: a normal direction (the developability budget)
// and a centre with a radius (compactness: round charts pack well; without
// it a torus falls into long curved bands).
struct ChartProxy {
  Vec3 normal;
  Vec3 center;
  double inv_radius2 = 0;  // 0 until the chart's size is known
};

struct Entry {
  double cost;
  int face, chart;
  bool operator>(const Entry& o) const { return cost > o.cost; }
};

// Normal misfit plus squared distance in chart radii, times `compactness`.
double fit_cost(const MeshTopology& t, int f, const ChartProxy& p, double compactness) {
  return norm2(t.face_normal[f] - p.normal) +
         compactness * norm2(t.face_centroid[f] - p.center) * p.inv_radius2;
}

// Grows every chart from its seed, cheapest face first. A face no seed can
// reach (enclosed by forced seams) becomes a new seed, so every face ends in a
// chart.
void flood(const MeshTopology& t, const std::vector<char>& seam, double compactness,
           std::vector<int>& seeds, std::vector<ChartProxy>& proxies, std::vector<int>& face_chart) {
  const int nf = static_cast<int>(face_chart.size());
  std::fill(face_chart.begin(), face_chart.end(), -1);
  std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> queue;
  auto push_neighbors = [&](int f, int c) {
    for (int k = 0; k < 3; ++k) {
      int g = t.face_neighbor[f][k];
      if (face_chart[g] < 0 && !seam[t.face_edge[f][k]])
        queue.push({fit_cost(t, g, proxies[c], compactness), g, c});
    }
  };
  int next_unassigned = 0;
  for (;;) {
    for (size_t c = 0; c < seeds.size(); ++c)
      if (face_chart[seeds[c]] < 0) {
        face_chart[seeds[c]] = static_cast<int>(c);
        push_neighbors(seeds[c], static_cast<int>(c));
      }
    while (!queue.empty()) {
      Entry e = queue.top();
      queue.pop();
      if (face_chart[e.face] >= 0) continue;
      face_chart[e.face] = e.chart;
      push_neighbors(e.face, e.chart);
    }
    while (next_unassigned < nf && face_chart[next_unassigned] >= 0) ++next_unassigned;
    if (next_unassigned == nf) break;
    seeds.push_back(next_unassigned);
    proxies.push_back({t.face_normal[next_unassigned], t.face_centroid[next_unassigned], 0});
  }
}

// Mean normal, centroid and radius of each chart, and the best-fitting face as
// its next seed.
void refit(const MeshTopology& t, const std::vector<int>& face_chart, double compactness,
           std::vector<int>& seeds, std::vector<ChartProxy>& proxies) {
  const int nf = static_cast<int>(face_chart.size());
  const int k = static_cast<int>(seeds.size());
  std::vector<Vec3> normal_sum(k, Vec3{0, 0, 0}), center_sum(k, Vec3{0, 0, 0});
  std::vector<double> area(k, 0);
  for (int f = 0; f < nf; ++f) {
    int c = face_chart[f];
    normal_sum[c] += t.face_area[f] * t.face_normal[f];
    center_sum[c] += t.face_area[f] * t.face_centroid[f];
    area[c] += t.face_area[f];
  }
  for (int c = 0; c < k; ++c) {
    Vec3 n = normalized(normal_sum[c]);
    // A chart whose normals cancel (a closed piece cut out by seams) has no
    // mean direction; its seed's normal is the next best axis.
    proxies[c].normal = norm2(n) > 0 ? n : t.face_normal[seeds[c]];
    if (area[c] > 0) {
      proxies[c].center = center_sum[c] / area[c];
      proxies[c].inv_radius2 = M_PI / area[c];
    }
  }
  std::vector<double> best(k, INFINITY);
  for (int f = 0; f < nf; ++f) {
    int c = face_chart[f];
    double cost = fit_cost(t, f, proxies[c], compactness);
    if (cost < best[c]) { best[c] = cost; seeds[c] = f; }
  }
}

// Faces that stick out of their chart (one neighbour in it, an "ear") move
// across their longest edge when another chart lies there, and faces with two
// neighbours in one other chart move to it: straighter boundaries, shorter
// seams, charts that pack tighter. An ear has one neighbour in its own chart,
// so moving it never disconnects that chart. Where three charts meet, a face
// is an ear of whichever chart owns it; across its longest edge it sticks out
// least (on grids of elongated quads the other way makes long spikes).
void smooth_boundaries(const MeshTopology& t, const std::vector<char>& seam, double cos_loose,
                       const std::vector<ChartProxy>& proxies, std::vector<int>& face_chart) {
  const int nf = static_cast<int>(face_chart.size());
  for (int pass = 0; pass < 8; ++pass) {
    int moved = 0;
    for (int f = 0; f < nf; ++f) {
      const int own = face_chart[f];
      int same = 0, majority = -1, longest = -1;
      double longest_len = -1;
      for (int k = 0; k < 3; ++k) {
        if (seam[t.face_edge[f][k]]) continue;
        int c = face_chart[t.face_neighbor[f][k]];
        if (c == own) ++same;
        else if (c == face_chart[t.face_neighbor[f][(k + 1) % 3]] ||
                 c == face_chart[t.face_neighbor[f][(k + 2) % 3]])
          majority = c;
        double len = t.edge_length[t.face_edge[f][k]];
        if (len > longest_len) { longest_len = len; longest = c; }
      }
      if (same != 1) continue;
      int target = majority >= 0 ? majority : longest;
      if (target < 0 || target == own || dot(t.face_normal[f], proxies[target].normal) < cos_loose)
        continue;
      face_chart[f] = target;
      ++moved;
    }
    if (!moved) break;
  }
}

}  // namespace

Segmentation segment_charts(const MeshTopology& t, const std::vector<char>& seam,
                            double max_deviation_deg, Progress& progress) {
  const int nf = static_cast<int>(t.face_area.size());
  const double cos_budget = std::cos(max_deviation_deg * M_PI / 180.0);
  // One chart radius away costs as much as a face at half the budget's
  // |n - N|^2 = 2 (1 - cos). Measured on the test shapes: without it tori fall
  // into long bands; at twice this weight cube faces start to split in two
  // and the worst utilisation gains only 0.015.
  const double compactness = 0.5 * 2 * (1 - cos_budget);
  std::vector<int> seeds{0};
  std::vector<ChartProxy> proxies{{t.face_normal[0], t.face_centroid[0], 0}};
  Segmentation s;
  s.face_chart.assign(nf, -1);

  // A Lloyd step between seed insertions lets charts settle before we judge
  // them against the budget. Seeds double per round at best, so 14 rounds
  // allow thousands of charts; the few charts still over budget then are
  // left to the stretch check, which splits what flattens badly.
  const int lloyd_steps = 1, max_rounds = 14;
  bool budget_met = false;
  for (int round = 0; round < max_rounds; ++round) {
    progress.update("atlas.segment", std::min(0.99, round / 20.0));
    s.rounds = round + 1;
    budget_met = false;
    for (int step = 0; step <= lloyd_steps; ++step) {
      flood(t, seam, compactness, seeds, proxies, s.face_chart);
      refit(t, s.face_chart, compactness, seeds, proxies);
      if (step < lloyd_steps) continue;
      const int k = static_cast<int>(seeds.size());
      std::vector<char> over_budget(k, 0);
      for (int f = 0; f < nf; ++f)
        if (t.face_area[f] > 0 && dot(t.face_normal[f], proxies[s.face_chart[f]].normal) < cos_budget)
          over_budget[s.face_chart[f]] = 1;
      // The new seed is the face turned farthest from the chart's seed: on a
      // chart of equally tilted faces (two cube sides) the worst face can be
      // the seed itself, but never the face farthest from it.
      std::vector<double> farthest_cos(k, 2.0);
      std::vector<int> farthest_face(k, -1);
      for (int f = 0; f < nf; ++f) {
        int c = s.face_chart[f];
        if (!over_budget[c] || t.face_area[f] <= 0) continue;
        double cs = dot(t.face_normal[f], t.face_normal[seeds[c]]);
        if (cs < farthest_cos[c]) { farthest_cos[c] = cs; farthest_face[c] = f; }
      }
      budget_met = true;
      for (int c = 0; c < k; ++c)
        if (over_budget[c] && farthest_face[c] >= 0 && farthest_face[c] != seeds[c]) {
          seeds.push_back(farthest_face[c]);
          // The new chart takes half its parent's area as its first radius;
          // with no radius at all it would flood far on the next pass.
          proxies.push_back({t.face_normal[farthest_face[c]], t.face_centroid[farthest_face[c]],
                             2 * proxies[c].inv_radius2});
          budget_met = false;
        }
    }
    if (budget_met) break;
  }
  // The last flood's partition is final (seeds moved after it, but its charts
  // met the budget).
  if (!budget_met) {
    flood(t, seam, compactness, seeds, proxies, s.face_chart);
    refit(t, s.face_chart, compactness, seeds, proxies);
  }
  // A protruding face sits at the rim of both charts' cones, so the strict
  // budget kept the spikes of elongated grid triangles (tori); half as much
  // again is allowed here, and the stretch check after flattening still
  // splits a chart that does not develop.
  const double cos_loose = std::cos(std::min(85.0, 1.5 * max_deviation_deg) * M_PI / 180.0);
  smooth_boundaries(t, seam, cos_loose, proxies, s.face_chart);
  // Renumber densely: a chart can lose every face to the smoothing.
  std::vector<int> remap(seeds.size(), -1);
  s.count = 0;
  for (int f = 0; f < nf; ++f) {
    int& r = remap[s.face_chart[f]];
    if (r < 0) r = s.count++;
    s.face_chart[f] = r;
  }
  return s;
}

}  // namespace soupuv::atlas
