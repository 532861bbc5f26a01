#include "geometry/pair_matching.h"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <queue>

namespace soupuv::geometry {

namespace {

// Union-find whose links carry the parity of the path to the parent.
class ParityUnionFind {
 public:
  explicit ParityUnionFind(uint32_t n) : parent_(n), parity_(n, 0) { std::iota(parent_.begin(), parent_.end(), 0u); }
  // Root of x and the parity of x relative to it.
  std::pair<uint32_t, uint8_t> find(uint32_t x) {
    uint8_t p = 0;
    uint32_t r = x;
    while (parent_[r] != r) p ^= parity_[r], r = parent_[r];
    // Path compression, keeping each node's parity to the root.
    uint8_t q = p;
    while (parent_[x] != x) {
      const uint32_t up = parent_[x];
      const uint8_t step = parity_[x];
      parent_[x] = r;
      parity_[x] = q;
      q ^= step;
      x = up;
    }
    return {r, p};
  }
  // Puts a and b on different sides; false when they are already on the
  // same side of one set (an odd cycle).
  bool join_apart(uint32_t a, uint32_t b) {
    const auto [ra, pa] = find(a);
    const auto [rb, pb] = find(b);
    if (ra == rb) return pa != pb;
    parent_[ra] = rb;
    parity_[ra] = pa ^ pb ^ 1;
    return true;
  }

 private:
  std::vector<uint32_t> parent_;
  std::vector<uint8_t> parity_;
};

// One part as a square assignment problem: rows are the left nodes, then
// one lone row per right node; columns are the right nodes, then one lone
// column per left node. Arcs per row (column, cost, candidate or -1).
struct Part {
  std::vector<uint32_t> left, right;  // global node ids
  std::vector<uint32_t> row_first;    // arcs of row i: [row_first[i], row_first[i+1])
  std::vector<uint32_t> arc_column;
  std::vector<double> arc_cost;
  std::vector<int64_t> arc_pair;
};

// Shortest augmenting paths; returns per row its column.
std::vector<uint32_t> solve_assignment(const Part& part) {
  const uint32_t nl = uint32_t(part.left.size()), nr = uint32_t(part.right.size());
  const uint32_t n = nl + nr;
  constexpr double kInf = std::numeric_limits<double>::infinity();
  constexpr uint32_t kNone = UINT32_MAX;
  std::vector<double> u(n, 0.0), v(n, 0.0), dist(n, kInf);
  std::vector<uint32_t> row_of(n, kNone), column_of(n, kNone), reached_from(n, kNone);
  std::vector<uint8_t> done(n, 0);
  std::vector<uint32_t> touched, finished;
  using Entry = std::pair<double, uint32_t>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> heap;
  for (uint32_t root = 0; root < n; ++root) {
    touched.clear();
    finished.clear();
    auto relax_from = [&](uint32_t row, double base) {
      for (uint32_t k = part.row_first[row]; k < part.row_first[row + 1]; ++k) {
        const uint32_t j = part.arc_column[k];
        if (done[j]) continue;
        const double d = base + part.arc_cost[k] - u[row] - v[j];
        if (d < dist[j]) {
          if (dist[j] == kInf) touched.push_back(j);
          dist[j] = d;
          reached_from[j] = row;
          heap.push({d, j});
        }
      }
    };
    relax_from(root, 0.0);
    uint32_t free_column = kNone;
    double D = 0;
    while (!heap.empty()) {
      const auto [d, j] = heap.top();
      heap.pop();
      if (done[j] || d > dist[j]) continue;
      done[j] = 1;
      finished.push_back(j);
      if (row_of[j] == kNone) {
        free_column = j;
        D = d;
        break;
      }
      relax_from(row_of[j], d);
    }
    while (!heap.empty()) heap.pop();
    // Every row has its lone column, so a free column is always reached.
    // Potentials: the finished columns (and the rows matched to them) by
    // how much closer than the free column they lie; the root by D.
    for (uint32_t j : finished) {
      if (j == free_column) continue;
      const double delta = D - dist[j];
      v[j] -= delta;
      u[row_of[j]] += delta;
    }
    u[root] += D;
    // Augment along the path back to the root.
    for (uint32_t j = free_column;;) {
      const uint32_t row = reached_from[j];
      const uint32_t previous = column_of[row];
      column_of[row] = j;
      row_of[j] = row;
      if (row == root) break;
      j = previous;
    }
    for (uint32_t j : touched) dist[j] = kInf, done[j] = 0;
  }
  return column_of;
}

}  // namespace

std::vector<uint8_t> least_cost_matching(uint32_t nodes, const std::vector<CandidatePair>& pairs, double unmatched,
                                         int threads) {
  std::vector<uint8_t> chosen(pairs.size(), 0);
  if (pairs.empty()) return chosen;
  std::vector<uint32_t> order(pairs.size());
  std::iota(order.begin(), order.end(), 0u);
  std::stable_sort(order.begin(), order.end(), [&](uint32_t x, uint32_t y) { return pairs[x].cost < pairs[y].cost; });

  // Sides by parity, cheapest pairs first; odd-cycle pairs left out.
  ParityUnionFind sides(nodes);
  std::vector<uint8_t> bipartite(pairs.size(), 0);
  for (uint32_t i : order) bipartite[i] = sides.join_apart(pairs[i].a, pairs[i].b);

  // Parts: the union-find's sets (every bipartite pair links two of its
  // nodes), numbered in node order.
  std::vector<uint32_t> part_of(nodes, UINT32_MAX), root_part(nodes, UINT32_MAX);
  std::vector<uint8_t> side(nodes, 0), used(nodes, 0);
  for (const CandidatePair& p : pairs) used[p.a] = used[p.b] = 1;
  uint32_t parts = 0;
  for (uint32_t x = 0; x < nodes; ++x) {
    if (!used[x]) continue;
    const auto [r, parity] = sides.find(x);
    if (root_part[r] == UINT32_MAX) root_part[r] = parts++;
    part_of[x] = root_part[r];
    side[x] = parity;
  }
  std::vector<Part> part(parts);
  std::vector<uint32_t> local(nodes, UINT32_MAX);
  for (uint32_t x = 0; x < nodes; ++x) {
    if (!used[x]) continue;
    Part& P = part[part_of[x]];
    auto& list = side[x] == 0 ? P.left : P.right;
    local[x] = uint32_t(list.size());
    list.push_back(x);
  }
  // Arcs per part: left rows' candidates and lone columns, then the lone
  // rows' right columns and the lone-to-lone arcs of each candidate.
  {
    std::vector<std::vector<uint32_t>> part_pairs(parts);
    for (uint32_t i = 0; i < pairs.size(); ++i)
      if (bipartite[i]) part_pairs[part_of[pairs[i].a]].push_back(i);
#pragma omp parallel for schedule(dynamic, 16) num_threads(std::max(1, threads))
    for (uint32_t k = 0; k < parts; ++k) {
      Part& P = part[k];
      const uint32_t nl = uint32_t(P.left.size()), nr = uint32_t(P.right.size()), n = nl + nr;
      std::vector<uint32_t> degree(n, 1);  // every row has its lone arc
      for (uint32_t i : part_pairs[k]) {
        const uint32_t l = side[pairs[i].a] == 0 ? pairs[i].a : pairs[i].b;
        const uint32_t r = side[pairs[i].a] == 0 ? pairs[i].b : pairs[i].a;
        ++degree[local[l]];
        ++degree[nl + local[r]];
      }
      P.row_first.assign(n + 1, 0);
      for (uint32_t row = 0; row < n; ++row) P.row_first[row + 1] = P.row_first[row] + degree[row];
      P.arc_column.resize(P.row_first[n]);
      P.arc_cost.resize(P.row_first[n]);
      P.arc_pair.resize(P.row_first[n]);
      std::vector<uint32_t> at(P.row_first.begin(), P.row_first.end() - 1);
      auto add = [&](uint32_t row, uint32_t column, double cost, int64_t pair) {
        P.arc_column[at[row]] = column, P.arc_cost[at[row]] = cost, P.arc_pair[at[row]] = pair, ++at[row];
      };
      for (uint32_t l = 0; l < nl; ++l) add(l, nr + l, unmatched, -1);
      for (uint32_t r = 0; r < nr; ++r) add(nl + r, r, unmatched, -1);
      for (uint32_t i : part_pairs[k]) {
        const uint32_t l = local[side[pairs[i].a] == 0 ? pairs[i].a : pairs[i].b];
        const uint32_t r = local[side[pairs[i].a] == 0 ? pairs[i].b : pairs[i].a];
        add(l, r, pairs[i].cost, int64_t(i));
        add(nl + r, nr + l, 0.0, -1);
      }
      const std::vector<uint32_t> column_of = solve_assignment(P);
      for (uint32_t l = 0; l < nl; ++l) {
        const uint32_t j = column_of[l];
        if (j >= nr) continue;
        for (uint32_t a = P.row_first[l]; a < P.row_first[l + 1]; ++a)
          if (P.arc_column[a] == j && P.arc_pair[a] >= 0) {
            chosen[size_t(P.arc_pair[a])] = 1;
            break;
          }
      }
      P = Part{};
    }
  }
  // The pairs left out, cheapest first, for nodes still alone.
  std::vector<uint8_t> matched(nodes, 0);
  for (uint32_t i = 0; i < pairs.size(); ++i)
    if (chosen[i]) matched[pairs[i].a] = matched[pairs[i].b] = 1;
  for (uint32_t i : order) {
    if (bipartite[i] || matched[pairs[i].a] || matched[pairs[i].b]) continue;
    chosen[i] = 1;
    matched[pairs[i].a] = matched[pairs[i].b] = 1;
  }
  return chosen;
}

}  // namespace soupuv::geometry
