#include "atlas/max_flow.h"

#include <algorithm>
#include <limits>
#include <queue>

namespace soupuv::atlas {

FlowGraph::FlowGraph(int nodes) : out_(nodes) {}

void FlowGraph::add_edge(int a, int b, double c) {
  out_[a].push_back(static_cast<int>(arcs_.size()));
  arcs_.push_back({b, c});
  out_[b].push_back(static_cast<int>(arcs_.size()));
  arcs_.push_back({a, c});
}

bool FlowGraph::build_levels(int source, int sink) {
  level_.assign(out_.size(), -1);
  std::queue<int> queue;
  level_[source] = 0;
  queue.push(source);
  while (!queue.empty()) {
    const int v = queue.front();
    queue.pop();
    for (int id : out_[v]) {
      const Arc& a = arcs_[id];
      if (a.residual > 0 && level_[a.to] < 0) {
        level_[a.to] = level_[v] + 1;
        queue.push(a.to);
      }
    }
  }
  return level_[sink] >= 0;
}

// Iterative would avoid deep recursion, but level graphs here are as deep as
// the band is wide (tens of faces), so recursion is bounded and clearer.
double FlowGraph::push(int v, int sink, double limit) {
  if (v == sink) return limit;
  for (int& i = next_arc_[v]; i < static_cast<int>(out_[v].size()); ++i) {
    const int id = out_[v][i];
    Arc& a = arcs_[id];
    if (a.residual <= 0 || level_[a.to] != level_[v] + 1) continue;
    const double pushed = push(a.to, sink, std::min(limit, a.residual));
    if (pushed > 0) {
      a.residual -= pushed;
      arcs_[id ^ 1].residual += pushed;
      return pushed;
    }
  }
  return 0;
}

MinCut FlowGraph::min_cut(int source, int sink) {
  MinCut cut;
  // Capacities are lengths: a residual this small relative to the largest is
  // rounding, and treating it as saturated ends the phases.
  double largest = 0;
  for (const Arc& a : arcs_) largest = std::max(largest, a.residual);
  const double tiny = 1e-12 * largest;
  for (Arc& a : arcs_)
    if (a.residual < tiny) a.residual = 0;
  while (build_levels(source, sink)) {
    next_arc_.assign(out_.size(), 0);
    for (;;) {
      const double f = push(source, sink, std::numeric_limits<double>::infinity());
      cut.capacity += f;
      if (f <= tiny) break;
    }
    for (Arc& a : arcs_)
      if (a.residual < tiny) a.residual = 0;
  }
  build_levels(source, sink);
  cut.source_side.resize(out_.size());
  for (size_t v = 0; v < out_.size(); ++v) cut.source_side[v] = level_[v] >= 0;
  return cut;
}

}  // namespace soupuv::atlas
