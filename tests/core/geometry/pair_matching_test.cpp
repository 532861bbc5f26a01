// geometry::least_cost_matching (geometry/pair_matching.h): the greedy's
// trap, and exactness against exhaustive search on small bipartite cases.
#include "geometry/pair_matching.h"

#include <gtest/gtest.h>

#include <functional>
#include <random>

using namespace soupuv::geometry;

namespace {

double total_cost(uint32_t nodes, const std::vector<CandidatePair>& pairs, const std::vector<uint8_t>& chosen,
                  double unmatched) {
  std::vector<int> uses(nodes, 0);
  double cost = 0;
  for (size_t i = 0; i < pairs.size(); ++i)
    if (chosen[i]) cost += pairs[i].cost, ++uses[pairs[i].a], ++uses[pairs[i].b];
  for (int u : uses) {
    EXPECT_LE(u, 1) << "a node in two chosen pairs";
    if (u == 0) cost += unmatched;
  }
  return cost;
}

// The least total over every matching, by exhaustive search.
double best_cost(uint32_t nodes, const std::vector<CandidatePair>& pairs, double unmatched) {
  std::vector<uint8_t> used(nodes, 0);
  double best = INFINITY;
  std::function<void(size_t, double, uint32_t)> go = [&](size_t i, double cost, uint32_t matched) {
    if (i == pairs.size()) {
      best = std::min(best, cost + unmatched * (nodes - matched));
      return;
    }
    go(i + 1, cost, matched);
    const CandidatePair& p = pairs[i];
    if (used[p.a] || used[p.b]) return;
    used[p.a] = used[p.b] = 1;
    go(i + 1, cost + p.cost, matched + 2);
    used[p.a] = used[p.b] = 0;
  };
  go(0, 0, 0);
  return best;
}

}  // namespace

// a - b - c - d: the cheapest pair (b, c) first would leave a and d alone;
// the least total pairs a with b and c with d.
TEST(PairMatching, AvoidsTheGreedyTrapOnAPath) {
  const std::vector<CandidatePair> pairs{{1, 2, 1.0}, {0, 1, 2.0}, {2, 3, 2.0}};
  const std::vector<uint8_t> chosen = least_cost_matching(4, pairs, 3.0, 1);
  EXPECT_EQ(chosen, (std::vector<uint8_t>{0, 1, 1}));
}

TEST(PairMatching, MatchesExhaustiveSearchOnRandomBipartiteCases) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> cost(0.0, 2.0);
  for (int round = 0; round < 200; ++round) {
    // Left nodes 0..4, right nodes 5..9, each pair with probability 0.4.
    std::vector<CandidatePair> pairs;
    for (uint32_t l = 0; l < 5; ++l)
      for (uint32_t r = 5; r < 10; ++r)
        if (std::uniform_real_distribution<double>(0, 1)(rng) < 0.4) pairs.push_back({l, r, cost(rng)});
    if (pairs.size() > 16) pairs.resize(16);
    const double unmatched = 1.0 + cost(rng) / 2;  // above half of every pair's cost
    const std::vector<uint8_t> chosen = least_cost_matching(10, pairs, unmatched, 2);
    EXPECT_NEAR(total_cost(10, pairs, chosen, unmatched), best_cost(10, pairs, unmatched), 1e-9) << "round " << round;
  }
}

// A triangle of pairs has an odd cycle: its dearest pair is left out of the
// exact problem and offered afterwards; every node still ends matched where
// it can be.
TEST(PairMatching, OddCyclesStillMatch) {
  const std::vector<CandidatePair> pairs{{0, 1, 1.0}, {1, 2, 1.5}, {0, 2, 2.0}, {2, 3, 3.0}};
  const std::vector<uint8_t> chosen = least_cost_matching(4, pairs, 10.0, 1);
  EXPECT_NEAR(total_cost(4, pairs, chosen, 10.0), best_cost(4, pairs, 10.0), 1e-12);
}
