// Minimum s-t cut of an undirected graph with real capacities, by maximum
// flow (Dinic 1970: BFS level graph, blocking flows by DFS).
//
// Inputs:  node count, undirected edges with capacity >= 0, source and sink.
// Output:  the cut's capacity and, per node, the side it falls on: 1 when the
//          node is reachable from the source in the residual graph (source
//          side), 0 otherwise. Among minimum cuts this is the one closest to
//          the source.
// Cost:    O(V^2 E) worst case; on the planar face graphs of seam relaxation
//          (a band of a few thousand faces) a handful of phases.
#pragma once

#include <vector>

namespace soupuv::atlas {

struct MinCut {
  double capacity = 0;
  std::vector<char> source_side;
};

class FlowGraph {
 public:
  explicit FlowGraph(int nodes);
  // An undirected edge: capacity c in both directions.
  void add_edge(int a, int b, double c);
  MinCut min_cut(int source, int sink);

 private:
  struct Arc {
    int to;
    double residual;
  };
  bool build_levels(int source, int sink);
  double push(int node, int sink, double limit);

  std::vector<Arc> arcs_;               // arc i and i^1 are each other's reverse
  std::vector<std::vector<int>> out_;   // arc ids leaving each node
  std::vector<int> level_, next_arc_;
};

}  // namespace soupuv::atlas
