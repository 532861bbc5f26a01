// A uniform hash grid over a soup's triangle corners, for the welds'
// "which corners lie near this point" query.
//
// Input : a soup, a cell size and the query reach (the callers' tolerance;
//         cells of half the reach visit ~8 reach^3 around p, where cells of
//         the reach visited 27 reach^3: a 124k scan's welds visited ~2,900
//         corners per query for ~440 within the tolerance).
// Output: for_each_near(p, f) calls f(corner id, position) for every corner
//         of the cells within the reach of p (the grid's, or one given per
//         query): every corner within the reach, and some beyond it. A fixed
//         order (cells x, then y, then z, each in corner order), so callers'
//         candidate lists are deterministic.
//         Built with_next, it also stores each corner's next corner in its
//         triangle (k + 1 mod 3) and f may take its position as a third
//         argument (only then: a grid built without it has no such
//         positions to give): the edge weld tests it for every corner near a query, and
//         reading it through the soup was a cache miss each (a 124k scan's
//         edge weld: 3.6 s of its 4.1 in that pass).
// Cost  : O(corners log corners) to build; a query costs its cells' corners
//         and one probe of an open-addressing table per cell (the cells of
//         half the reach make ~125 of them a query: in a std::unordered_map
//         their bucket chains were most of a 124k scan's weld time).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <type_traits>
#include <vector>

#include "soupuv/soup.h"

namespace soupuv::geometry {

class CornerGrid {
 public:
  CornerGrid(const Soup& soup, const Box3& box, double cell, double reach, bool with_next = false)
      : lo_(box.lo), cell_(cell), reach_(reach) {
    const size_t corners = soup.triangles.size() * 3;
    // Corners sorted by cell (stable: corner order within a cell), stored
    // with their positions so a query reads one contiguous run per cell
    // (the soup's corner -> vertex -> position chain was most of a weld's
    // time on a 124k scan).
    std::vector<std::pair<uint64_t, uint32_t>> keyed(corners);
    for (size_t c = 0; c < corners; ++c) {
      const Vec3 p = soup.positions[soup.triangles[c / 3][c % 3]];
      keyed[c] = {key(coord(p.x, lo_.x), coord(p.y, lo_.y), coord(p.z, lo_.z)), uint32_t(c)};
    }
    std::sort(keyed.begin(), keyed.end());
    entries_.resize(corners);
    if (with_next) {
      next_.resize(corners);
      for (size_t i = 0; i < corners; ++i) {
        const uint32_t c = keyed[i].second, n = c - c % 3 + (c % 3 + 1) % 3;
        next_[i] = soup.positions[soup.triangles[n / 3][n % 3]];
      }
    }
    size_t cells = 0;
    for (size_t i = 0; i < corners; ++i) cells += i == 0 || keyed[i].first != keyed[i - 1].first;
    int bits = 1;
    while ((size_t(1) << bits) < 2 * cells) ++bits;
    shift_ = 64 - bits;
    slots_.assign(size_t(1) << bits, Slot{kEmpty, 0, 0});
    for (size_t i = 0; i < corners;) {
      size_t e = i;
      while (e < corners && keyed[e].first == keyed[i].first) {
        const uint32_t c = keyed[e].second;
        entries_[e] = {soup.positions[soup.triangles[c / 3][c % 3]], c};
        ++e;
      }
      size_t h = slot_of(keyed[i].first);
      while (slots_[h].key != kEmpty) h = (h + 1) & (slots_.size() - 1);
      slots_[h] = {keyed[i].first, uint32_t(i), uint32_t(e)};
      i = e;
    }
  }

  // visit(first, end, centre) for every non-empty cell: its entries
  // [first, end) (entry_corner, entry_position, entry_next) and its centre,
  // in no particular order. For callers that batch the queries of one cell
  // (for_each_near_cell).
  template <class Visit>
  void for_each_cell(Visit&& visit) const {
    for (const Slot& s : slots_) {
      if (s.key == kEmpty) continue;
      const int64_t x = int64_t(s.key & 0x1fffff), y = int64_t((s.key >> 21) & 0x1fffff),
                    z = int64_t((s.key >> 42) & 0x1fffff);
      visit(s.first, s.end, Vec3{lo_.x + (double(x) + 0.5) * cell_, lo_.y + (double(y) + 0.5) * cell_,
                                 lo_.z + (double(z) + 0.5) * cell_});
    }
  }
  // visit(corner, position[, next position]) for every corner of the cells
  // that come within the grid's reach of the cell holding p (box to box):
  // every corner within the reach of any point of that cell. A fixed order.
  // on_cell(lo, hi) is called before each non-empty cell's corners with
  // the cell's box.
  template <class OnCell, class Visit>
  void for_each_near_cell(const Vec3& p, OnCell&& on_cell, Visit&& visit) const {
    if constexpr (std::is_invocable_v<Visit, uint32_t, const Vec3&, const Vec3&>)
      if (next_.size() != entries_.size()) std::abort();  // built without with_next: a caller's bug
    const double reach2 = reach_ * reach_ * (1 + 1e-9);
    const int64_t r = int64_t(std::ceil(reach_ / cell_ * (1 + 1e-9)));
    const int64_t cx = coord(p.x, lo_.x), cy = coord(p.y, lo_.y), cz = coord(p.z, lo_.z);
    // The gap between two cells d apart along an axis.
    auto gap2 = [&](int64_t d) {
      const double g = double(std::max<int64_t>(std::abs(d) - 1, 0)) * cell_;
      return g * g;
    };
    for (int64_t x = std::max<int64_t>(cx - r, 0); x <= cx + r; ++x) {
      const double gx = gap2(x - cx);
      if (gx > reach2) continue;
      for (int64_t y = std::max<int64_t>(cy - r, 0); y <= cy + r; ++y) {
        const double gxy = gx + gap2(y - cy);
        if (gxy > reach2) continue;
        for (int64_t z = std::max<int64_t>(cz - r, 0); z <= cz + r; ++z) {
          if (gxy + gap2(z - cz) > reach2) continue;
          const Slot* cell = find(key(x, y, z));
          if (!cell) continue;
          const Vec3 lo{lo_.x + double(x) * cell_, lo_.y + double(y) * cell_, lo_.z + double(z) * cell_};
          on_cell(lo, Vec3{lo.x + cell_, lo.y + cell_, lo.z + cell_});
          visit_entries(*cell, visit);
        }
      }
    }
  }
  uint32_t entry_corner(size_t i) const { return entries_[i].corner; }
  const Vec3& entry_position(size_t i) const { return entries_[i].position; }
  const Vec3& entry_next(size_t i) const { return next_[i]; }

  // visit(corner, position) for every corner of the cells that come within
  // `reach` of p, cell by cell (x, then y, then z), each in corner order.
  template <class Visit>
  void for_each_near(const Vec3& p, Visit&& visit) const {
    for_each_near(p, reach_, visit);
  }
  // The same within a reach of this query's own (a caller that knows its
  // partners lie closer than the grid's reach visits fewer cells).
  template <class Visit>
  void for_each_near(const Vec3& p, double reach, Visit&& visit) const {
    if constexpr (std::is_invocable_v<Visit, uint32_t, const Vec3&, const Vec3&>)
      if (next_.size() != entries_.size()) std::abort();  // built without with_next: a caller's bug
    // A hair over the reach: a cell bound's rounding never drops a corner.
    const double reach2 = reach * reach * (1 + 1e-9);
    const int64_t x0 = coord(p.x - reach, lo_.x), x1 = coord(p.x + reach, lo_.x);
    const int64_t y0 = coord(p.y - reach, lo_.y), y1 = coord(p.y + reach, lo_.y);
    const int64_t z0 = coord(p.z - reach, lo_.z), z1 = coord(p.z + reach, lo_.z);
    // Squared distance from p to cell i's slab along one axis; 0 for p's own
    // cell (whatever the rounding of its bounds: a reach of 0 finds copies).
    auto gap2 = [&](double v, double lo, int64_t i) {
      if (i == coord(v, lo)) return 0.0;
      const double a = lo + double(i) * cell_, b = a + cell_;
      const double d = v < a ? a - v : v > b ? v - b : 0.0;
      return d * d;
    };
    for (int64_t x = std::max<int64_t>(x0, 0); x <= x1; ++x) {
      const double gx = gap2(p.x, lo_.x, x);
      if (gx > reach2) continue;
      for (int64_t y = std::max<int64_t>(y0, 0); y <= y1; ++y) {
        const double gxy = gx + gap2(p.y, lo_.y, y);
        if (gxy > reach2) continue;
        for (int64_t z = std::max<int64_t>(z0, 0); z <= z1; ++z) {
          if (gxy + gap2(p.z, lo_.z, z) > reach2) continue;
          const Slot* cell = find(key(x, y, z));
          if (!cell) continue;
          visit_entries(*cell, visit);
        }
      }
    }
  }

 private:
  struct Slot;
  // visit(corner, position[, next position]) for each entry of one cell.
  template <class Visit>
  void visit_entries(const Slot& cell, Visit& visit) const {
    for (uint32_t i = cell.first; i < cell.end; ++i) {
      if constexpr (std::is_invocable_v<Visit, uint32_t, const Vec3&, const Vec3&>)
        visit(entries_[i].corner, entries_[i].position, next_[i]);
      else
        visit(entries_[i].corner, entries_[i].position);
    }
  }
  struct Entry {
    Vec3 position;
    uint32_t corner;
  };
  // floor((v - lo) / cell) without a call to floor (it was not inlined).
  int64_t coord(double v, double lo) const {
    const double t = (v - lo) / cell_;
    const int64_t i = int64_t(t);
    return double(i) > t ? i - 1 : i;
  }
  // 21 bits per axis: callers keep the grid within 2^20 cells per axis, and
  // coordinates are offset by the box minimum.
  static uint64_t key(int64_t x, int64_t y, int64_t z) {
    return (uint64_t(x) & 0x1fffff) | ((uint64_t(y) & 0x1fffff) << 21) |
           ((uint64_t(z) & 0x1fffff) << 42);
  }

  // A cell's entries [first, end), in an open-addressing table (linear
  // probing, at most half full). Keys use 63 bits, so kEmpty is none.
  struct Slot {
    uint64_t key;
    uint32_t first, end;
  };
  static constexpr uint64_t kEmpty = ~uint64_t(0);
  size_t slot_of(uint64_t k) const { return size_t((k * 0x9E3779B97F4A7C15ull) >> shift_); }
  const Slot* find(uint64_t k) const {
    for (size_t h = slot_of(k);; h = (h + 1) & (slots_.size() - 1)) {
      if (slots_[h].key == k) return &slots_[h];
      if (slots_[h].key == kEmpty) return nullptr;
    }
  }

  Vec3 lo_;
  double cell_, reach_;
  std::vector<Entry> entries_;
  std::vector<Vec3> next_;  // with_next: the next corner's position, by entry
  std::vector<Slot> slots_;
  int shift_ = 63;
};

}  // namespace soupuv::geometry
