// Least-cost matching of candidate pairs (private to geometry; the edge
// weld matches soup edges with it).
//
// Input : the node count, candidate pairs (two distinct nodes and a cost
//         >= 0 each) and the cost of leaving one node unmatched (above half
//         of every pair's cost, so any pair is worth more than two lone
//         nodes).
// Output: per candidate pair, whether it is chosen: no node in two chosen
//         pairs, and the sum of the chosen pairs' costs plus `unmatched`
//         per node left alone is least over the matchings of the bipartite
//         part of the candidates (below); pairs left out of it are offered
//         afterwards, cheapest first, to nodes still alone.
// Method: the nodes are split in two sides by parity along the cheapest
//         pairs first (union-find with parity); a pair that would close an
//         odd cycle is left out, so what remains is bipartite. Each
//         connected part is an assignment problem, square once each node
//         gets a private "alone" partner on the other side (the lone
//         partners matched to each other at no cost), solved exactly by
//         shortest augmenting paths (Dijkstra on reduced costs, one
//         augmentation per row; the Hungarian method with Jonker and
//         Volgenant's potentials). Parts are solved in parallel.
// Why   : a greedy matching, cheapest pair first, takes a wrong partner
//         whenever noise makes it the closest, and its right partner then
//         has to settle for another wrong one; where a soup's rows of thin
//         triangles are narrower than its noise (a bolt's shank, a table
//         leg's fillet) the greedy weld joined one edge in ten to the row
//         beside it. The least total cost keeps each row with its own
//         (docs/tuning.md, "The edge weld as an assignment").
// Cost  : per part of k nodes and m pairs, O(k m log k) at worst; the
//         searches stop at the first free partner and stay local on soups.
#pragma once

#include <cstdint>
#include <vector>

namespace soupuv::geometry {

struct CandidatePair {
  uint32_t a, b;
  double cost;
};

std::vector<uint8_t> least_cost_matching(uint32_t nodes, const std::vector<CandidatePair>& pairs,
                                         double unmatched, int threads);

}  // namespace soupuv::geometry
