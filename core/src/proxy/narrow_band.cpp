// Coarse-to-fine narrow band of f = d - o. See soupuv/proxy/narrow_band.h.
#include "soupuv/proxy/narrow_band.h"

#include <algorithm>
#include <bit>
#include <cmath>

#include "soupuv/errors.h"

namespace soupuv::proxy {

std::array<double, 8> NarrowBand::cell_values(size_t n) const {
  std::array<double, 8> f;
  if (cell_corners.size() == cells.size()) {
    for (int v = 0; v < 8; ++v) f[v] = corner_values[cell_corners[n][v]];
  } else {
    auto c = grid_coords(cells[n]);
    for (int v = 0; v < 8; ++v) f[v] = value(grid_key(c[0] + (v & 1), c[1] + ((v >> 1) & 1), c[2] + (v >> 2)));
  }
  return f;
}

double NarrowBand::value(uint64_t key) const {
  auto it = std::lower_bound(corner_keys.begin(), corner_keys.end(), key);
  if (it == corner_keys.end() || *it != key)
    throw Error(ErrorCode::internal, "narrow band: corner outside the band");
  return corner_values[it - corner_keys.begin()];
}

namespace {

enum Label : uint8_t { kInside = 0, kOutside = 1, kBand = 2, kReached = 4, kBlocked = 8 };

// A cell dropped as certainly outside at some level: painted into the dense
// label grid of every finer level that is pruned.
struct OutsideCell {
  int level;
  uint64_t key;
};

// Marks the band cells of `level` that the region reachable from the grid
// border (through cells not certainly inside, 6-connected) never touches;
// returns false in `keep` for them. `labels` holds kInside/kOutside/kBand per
// current cell; `outside` the certainly-outside cells of all coarser levels.
size_t prune_cavities(const std::array<int, 3>& dims, int level, const std::vector<uint64_t>& current,
                      const std::vector<uint8_t>& labels, const std::vector<OutsideCell>& outside,
                      std::vector<char>& keep, std::vector<char>& reached_cell) {
  const int64_t n[3] = {(dims[0] + (1 << level) - 1) >> level, (dims[1] + (1 << level) - 1) >> level,
                        (dims[2] + (1 << level) - 1) >> level};
  // The label grid has a one-cell frame of kBlocked around it, so the flood
  // needs no bounds checks: a neighbour is always at id +- 1, +- sx, +- sxy.
  const int64_t sx = n[0] + 2, sxy = sx * (n[1] + 2);
  const int64_t total = sxy * (n[2] + 2);
  auto index = [&](int64_t i, int64_t j, int64_t k) { return (i + 1) + sx * (j + 1) + sxy * (k + 1); };
  std::vector<uint8_t> grid(size_t(total), kInside);
  for (int64_t k = -1; k <= n[2]; ++k)
    for (int64_t j = -1; j <= n[1]; ++j)
      for (int64_t i = -1; i <= n[0]; ++i)
        if (i < 0 || j < 0 || k < 0 || i == n[0] || j == n[1] || k == n[2]) grid[size_t(index(i, j, k))] = kBlocked;
  for (const OutsideCell& o : outside) {
    auto c = grid_coords(o.key);
    int64_t scale = int64_t{1} << (o.level - level);
    int64_t lo[3], hi[3];
    for (int a = 0; a < 3; ++a) {
      lo[a] = c[a] * scale;
      hi[a] = std::min<int64_t>(lo[a] + scale, n[a]);
    }
    for (int64_t k = lo[2]; k < hi[2]; ++k)
      for (int64_t j = lo[1]; j < hi[1]; ++j)
        std::fill(grid.begin() + index(lo[0], j, k), grid.begin() + index(hi[0], j, k), uint8_t(kOutside));
  }
  for (size_t m = 0; m < current.size(); ++m) {
    auto c = grid_coords(current[m]);
    grid[size_t(index(c[0], c[1], c[2]))] = labels[m];
  }
  // Flood from the border through every cell that is not certainly inside,
  // one BFS layer at a time (memory: two wavefronts, not the whole volume).
  std::vector<uint32_t> frontier, next;
  auto push = [&](int64_t id, std::vector<uint32_t>& into) {
    uint8_t& g = grid[size_t(id)];
    if (g == kInside || (g & (kReached | kBlocked))) return;
    g |= kReached;
    into.push_back(uint32_t(id));
  };
  for (int64_t k = 0; k < n[2]; ++k)
    for (int64_t j = 0; j < n[1]; ++j)
      for (int64_t i = 0; i < n[0]; ++i)
        if (i == 0 || j == 0 || k == 0 || i == n[0] - 1 || j == n[1] - 1 || k == n[2] - 1)
          push(index(i, j, k), frontier);
  const int64_t step[6] = {1, -1, sx, -sx, sxy, -sxy};
  while (!frontier.empty()) {
    next.clear();
    for (uint32_t id : frontier)
      for (int64_t d : step) push(int64_t(id) + d, next);
    frontier.swap(next);
  }
  size_t pruned = 0;
  for (size_t m = 0; m < current.size(); ++m) {
    auto c = grid_coords(current[m]);
    reached_cell[m] = (grid[size_t(index(c[0], c[1], c[2]))] & kReached) != 0;
    if (keep[m] && !reached_cell[m]) {
      keep[m] = 0;
      ++pruned;
    }
  }
  return pruned;
}

}  // namespace

NarrowBand build_narrow_band(const geometry::DistanceBvh& bvh, const Box3& box, double offset,
                             double cell, Progress& progress, bool outer_only) {
  NarrowBand band;
  band.offset = offset;
  band.cell = cell;
  double pad = offset + 2 * cell;
  band.origin = box.lo - Vec3{pad, pad, pad};
  Vec3 ext = box.extent() + Vec3{2 * pad, 2 * pad, 2 * pad};
  for (int a = 0; a < 3; ++a) {
    band.dims[a] = static_cast<int>(std::ceil(ext[a] / cell));
    if (band.dims[a] >= (1 << kGridBits) - 2)
      throw Error(ErrorCode::limit_exceeded, "proxy grid too fine for the offset");
  }
  // Top level: cells of 2^levels fine cells, about 8 along the longest axis;
  // at least one level above the leaves, whose cells group the leaf corners.
  int longest = std::max({band.dims[0], band.dims[1], band.dims[2]});
  int levels = 1;
  while ((longest >> levels) > 8) ++levels;

  std::vector<uint64_t> current;
  int top = 1 << levels;
  for (int k = 0; k * top < band.dims[2]; ++k)
    for (int j = 0; j * top < band.dims[1]; ++j)
      for (int i = 0; i * top < band.dims[0]; ++i) current.push_back(grid_key(i, j, k));
  // Closest soup triangle found for each cell's center, handed to its
  // children as a warm start: nearby points mostly share their closest
  // triangle, so the search starts with a tight bound.
  std::vector<uint32_t> hint(current.size(), UINT32_MAX);

  // Cell c's box and center at a level of cells of `size`.
  auto box_of = [&](uint64_t key, double size) {
    auto c = grid_coords(key);
    Box3 b;
    b.lo = band.origin + Vec3{c[0] * size, c[1] * size, c[2] * size};
    b.hi = band.origin + Vec3{(c[0] + 1) * size, (c[1] + 1) * size, (c[2] + 1) * size};
    return b;
  };
  auto center_of = [&](uint64_t key, double size) { return box_of(key, size).center(); };
  // The kept cells of the level above, as the parents of the current cells
  // (contiguous children [begin, end)): any point p of a parent's box has
  // d(p) <= d(center) + half-diagonal, so its closest triangle lies within
  // that radius of the box and is in the parent's gathered candidate list.
  struct Parent {
    Box3 box;
    double radius;
    size_t begin, end;
    uint32_t up;  // its own parent in `grandparents`
  };
  std::vector<Parent> parents, grandparents;
  std::vector<uint32_t> parent_of;  // per current cell
  // A query answering "hi" for every distance >= hi needs no triangle farther
  // than hi from the box: if the closest one is, every point's answer is hi.
  auto capped = [](double radius, double hi) { return std::min(radius, hi * (1 + 1e-9)); };
  // Calls visit(p, list) for every parent p that `needs` a list, in
  // parallel, with its candidate list for queries answering up to `hi`.
  // Parents of one grandparent (contiguous, same `up`) share one BVH gather
  // around the grandparent's box, narrowed per parent: a parent's radius is
  // no larger than the largest of its run.
  auto for_each_parent_list = [&](double hi, auto&& needs, auto&& visit) {
    std::vector<size_t> runs;
    for (size_t p = 0; p < parents.size(); ++p)
      if (p == 0 || grandparents.empty() || parents[p].up != parents[p - 1].up) runs.push_back(p);
    runs.push_back(parents.size());
    const long n_runs = long(runs.size()) - 1;
#pragma omp parallel
    {
      geometry::CandidateList shared, list;
#pragma omp for schedule(dynamic, 4)
      for (long r = 0; r < n_runs; ++r) {
        double radius = 0;
        size_t needed = 0, last = 0;
        for (size_t p = runs[size_t(r)]; p < runs[size_t(r) + 1]; ++p)
          if (needs(p)) {
            radius = std::max(radius, capped(parents[p].radius, hi));
            ++needed;
            last = p;
          }
        if (needed == 0) continue;
        if (needed == 1) {
          bvh.gather(parents[last].box, capped(parents[last].radius, hi), list);
          visit(last, list);
          continue;
        }
        bvh.gather(grandparents[parents[runs[size_t(r)]].up].box, radius, shared);
        for (size_t p = runs[size_t(r)]; p < runs[size_t(r) + 1]; ++p) {
          if (!needs(p)) continue;
          bvh.narrow(shared, parents[p].box, capped(parents[p].radius, hi), list);
          visit(p, list);
        }
      }
    }
  };
  std::vector<double> distances;  // per current cell: d(center), exact when kept

  size_t evaluations = 0;
  std::vector<OutsideCell> outside;  // certainly-outside cells of coarser levels
  // Refine down to cells of size h by the Lipschitz test on their centers
  // (and the cavity pruning); the survivors of level 0 are the candidate
  // leaves, decided by their corners below. Testing level 0 too costs one
  // distance per candidate and drops about half of them before their corners.
  for (int level = levels; level >= 0; --level) {
    progress.update("proxy: narrow band", double(levels - level) / (levels + 1));
    double size = cell * (1 << level);
    double half_diagonal = 0.5 * std::sqrt(3.0) * size * (1 + 1e-9);
    std::vector<char> keep(current.size());
    std::vector<uint8_t> labels(current.size());
    distances.assign(current.size(), 0.0);
    // A cell can hold the level set only if |d(center) - o| <= half-diagonal.
    // distance() answers exactly inside (lo, hi), below lo or == hi outside
    // it, so the test must be strict at both ends.
    const double lo = offset - half_diagonal, hi = offset + half_diagonal;
    auto decide = [&](size_t n, double d) {
      distances[n] = d;
      keep[n] = d > lo && d < hi;
      labels[n] = keep[n] ? kBand : d >= hi ? kOutside : kInside;
    };
    // Candidate lists pay once a parent's box is small against the offset
    // (a list holds the triangles within about o of the box); above that a
    // BVH descent per center is cheaper than scanning a long list.
    if (!parents.empty() && 2 * size <= 2 * offset) {
      for_each_parent_list(
          hi, [](size_t) { return true; },
          [&](size_t p, const geometry::CandidateList& list) {
            for (size_t n = parents[p].begin; n < parents[p].end; ++n)
              decide(n, bvh.distance_among(center_of(current[n], size), list, lo, hi, &hint[n]));
          });
    } else {
#pragma omp parallel for schedule(dynamic, 256)
      for (long n = 0; n < long(current.size()); ++n)
        decide(size_t(n), bvh.distance(center_of(current[size_t(n)], size), lo, hi, &hint[size_t(n)]));
    }
    evaluations += current.size();
    const int64_t cells_at_level = int64_t((band.dims[0] >> level) + 1) * ((band.dims[1] >> level) + 1) *
                                   ((band.dims[2] >> level) + 1);
    std::vector<char> reached(current.size(), 1);
    if (outer_only && cells_at_level <= (int64_t{1} << 25))
      band.pruned_cells += prune_cavities(band.dims, level, current, labels, outside, keep, reached);
    // Certainly-outside cells the border reaches matter to finer levels'
    // floods; enclosed ones (cavities) never will.
    if (outer_only && level > 0)
      for (size_t n = 0; n < current.size(); ++n)
        if (labels[n] == kOutside && reached[n]) outside.push_back({level, current[n]});
    if (level == 0) {
      size_t kept = 0;
      for (size_t n = 0; n < current.size(); ++n)
        if (keep[n]) {
          current[kept] = current[n];
          parent_of[kept] = parent_of[n];
          hint[kept++] = hint[n];
        }
      current.resize(kept);
      hint.resize(kept);
      parent_of.resize(kept);
      break;
    }
    std::vector<uint64_t> next;
    std::vector<uint32_t> next_hint, next_parent;
    std::vector<Parent> next_parents;
    const int child_size = 1 << (level - 1);
    for (size_t n = 0; n < current.size(); ++n) {
      if (!keep[n]) continue;
      next_parents.push_back({box_of(current[n], size), (distances[n] + half_diagonal) * (1 + 1e-7), next.size(), 0,
                              parent_of.empty() ? 0u : parent_of[n]});
      auto c = grid_coords(current[n]);
      for (int dz = 0; dz < 2; ++dz)
        for (int dy = 0; dy < 2; ++dy)
          for (int dx = 0; dx < 2; ++dx) {
            int i = 2 * c[0] + dx, j = 2 * c[1] + dy, k = 2 * c[2] + dz;
            if (i * child_size < band.dims[0] && j * child_size < band.dims[1] && k * child_size < band.dims[2]) {
              next.push_back(grid_key(i, j, k));
              next_hint.push_back(hint[n]);
              next_parent.push_back(uint32_t(next_parents.size() - 1));
            }
          }
      next_parents.back().end = next.size();
    }
    current.swap(next);
    hint.swap(next_hint);
    parent_of.swap(next_parent);
    grandparents.swap(parents);
    parents.swap(next_parents);
  }

  // Corners of the candidate leaves. The leaves of one parent (a kept
  // level-1 cell) have their corners on the parent's 3x3x3 lattice: a bit
  // mask per parent removes the duplicates inside it, a sort by key those
  // between parents. Each unique corner is evaluated by the first parent
  // listing it (its "owner"), with that parent's candidate list.
  auto lattice_bit = [](int a, int b, int c) { return a + 3 * b + 9 * c; };
  std::vector<uint32_t> mask(parents.size(), 0);
  for (size_t n = 0; n < current.size(); ++n) {
    auto c = grid_coords(current[n]);
    const uint32_t g = parent_of[n];
    const int a = c[0] & 1, b = c[1] & 1, z = c[2] & 1;  // position inside the parent
    for (int v = 0; v < 8; ++v) mask[g] |= 1u << lattice_bit(a + (v & 1), b + ((v >> 1) & 1), z + (v >> 2));
  }
  // Slot: a (parent, lattice point) pair, numbered parent by parent.
  std::vector<uint32_t> slot_start(parents.size() + 1, 0);
  for (size_t g = 0; g < parents.size(); ++g) slot_start[g + 1] = slot_start[g] + uint32_t(std::popcount(mask[g]));
  auto slot_of = [&](uint32_t g, int bit) {
    return slot_start[g] + uint32_t(std::popcount(mask[g] & ((1u << bit) - 1)));
  };
  struct Entry {
    uint64_t key;
    uint32_t slot;
  };
  std::vector<Entry> entries;
  entries.reserve(slot_start.back());
  // The parent's lowest lattice point is twice its level-1 coordinates; the
  // level-1 key is not stored, so take it from any of its leaves.
  std::vector<uint64_t> parent_origin(parents.size(), 0);
  for (size_t n = 0; n < current.size(); ++n) {
    auto c = grid_coords(current[n]);
    parent_origin[parent_of[n]] = grid_key(c[0] & ~1, c[1] & ~1, c[2] & ~1);
  }
  for (size_t g = 0; g < parents.size(); ++g) {
    if (!mask[g]) continue;
    auto o = grid_coords(parent_origin[g]);
    for (int bit = 0; bit < 27; ++bit)
      if (mask[g] >> bit & 1)
        entries.push_back({grid_key(o[0] + bit % 3, o[1] + (bit / 3) % 3, o[2] + bit / 9), slot_of(uint32_t(g), bit)});
  }
  std::sort(entries.begin(), entries.end(), [](const Entry& x, const Entry& y) {
    return x.key < y.key || (x.key == y.key && x.slot < y.slot);
  });
  // Unique corners in key order; slot -> corner index; owners evaluate.
  std::vector<uint32_t> corner_of_slot(slot_start.back());
  std::vector<char> owns(slot_start.back(), 0);
  for (size_t e = 0; e < entries.size(); ++e) {
    if (e == 0 || entries[e].key != entries[e - 1].key) {
      band.corner_keys.push_back(entries[e].key);
      owns[entries[e].slot] = 1;
    }
    corner_of_slot[entries[e].slot] = uint32_t(band.corner_keys.size() - 1);
  }
  std::vector<Entry>().swap(entries);
  band.corner_values.resize(band.corner_keys.size());
  progress.update("proxy: narrow band", double(levels) / (levels + 1));

  // Corner values. A corner of a cell the level set crosses is within
  // sqrt(3) h of it, so a band query of o +- 1.75 h gives exact values
  // wherever they are used (1-Lipschitz); values outside the band only need
  // their sign. Warm start: the closest triangle of a leaf center nearby.
  const double band_width = 1.75 * cell;  // > sqrt(3) h
  const double corner_lo = offset - band_width, corner_hi = offset + band_width;
  std::vector<uint32_t> parent_hint(parents.size(), UINT32_MAX);
  for (size_t n = 0; n < current.size(); ++n) parent_hint[parent_of[n]] = hint[n];
  std::vector<char> owner(parents.size(), 0);
  for (size_t g = 0; g < parents.size(); ++g)
    for (uint32_t slot = slot_start[g]; slot < slot_start[g + 1]; ++slot) owner[g] |= owns[slot];
  for_each_parent_list(
      corner_hi, [&](size_t g) { return owner[g] != 0; },
      [&](size_t g, const geometry::CandidateList& list) {
        auto o = grid_coords(parent_origin[g]);
        uint32_t warm = parent_hint[g];
        for (int bit = 0; bit < 27; ++bit) {
          if (!(mask[g] >> bit & 1)) continue;
          uint32_t slot = slot_of(uint32_t(g), bit);
          if (!owns[slot]) continue;
          uint64_t key = grid_key(o[0] + bit % 3, o[1] + (bit / 3) % 3, o[2] + bit / 9);
          double d = bvh.distance_among(band.corner_position(key), list, corner_lo, corner_hi, &warm);
          band.corner_values[corner_of_slot[slot]] = d - offset;
        }
      });
  // Leaves: the candidates whose corners change sign; the others hold no
  // surface. Their unused corners stay (harmless, and lookups stay simple).
  std::vector<std::array<uint32_t, 8>> corners_of(current.size());
  std::vector<char> crossing(current.size());
#pragma omp parallel for schedule(static)
  for (long n = 0; n < long(current.size()); ++n) {
    auto c = grid_coords(current[size_t(n)]);
    const uint32_t g = parent_of[size_t(n)];
    const int a = c[0] & 1, b = c[1] & 1, z = c[2] & 1;
    int inside = 0;
    for (int v = 0; v < 8; ++v) {
      uint32_t index = corner_of_slot[slot_of(g, lattice_bit(a + (v & 1), b + ((v >> 1) & 1), z + (v >> 2)))];
      corners_of[size_t(n)][v] = index;
      inside += band.corner_values[index] < 0;
    }
    crossing[size_t(n)] = inside != 0 && inside != 8;
  }
  // Leaves in key order (marching cubes' output order follows them).
  std::vector<uint32_t> order;
  for (size_t n = 0; n < current.size(); ++n)
    if (crossing[n]) order.push_back(uint32_t(n));
  std::sort(order.begin(), order.end(), [&](uint32_t x, uint32_t y) { return current[x] < current[y]; });
  band.cells.resize(order.size());
  band.cell_corners.resize(order.size());
  for (size_t m = 0; m < order.size(); ++m) {
    band.cells[m] = current[order[m]];
    band.cell_corners[m] = corners_of[order[m]];
  }
  band.distance_evaluations = evaluations + band.corner_keys.size();
  return band;
}

}  // namespace soupuv::proxy
