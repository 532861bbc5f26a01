// Coarse-to-fine narrow band of f = d - o. See soupuv/proxy/narrow_band.h.
#include "soupuv/proxy/narrow_band.h"

#include <algorithm>
#include <cmath>

#include "soupuv/errors.h"

namespace soupuv::proxy {

double NarrowBand::value(uint64_t key) const {
  auto it = std::lower_bound(corner_keys.begin(), corner_keys.end(), key);
  if (it == corner_keys.end() || *it != key)
    throw Error(ErrorCode::internal, "narrow band: corner outside the band");
  return corner_values[it - corner_keys.begin()];
}

namespace {

enum Label : uint8_t { kInside = 0, kOutside = 1, kBand = 2, kReached = 4 };

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
  const int64_t total = n[0] * n[1] * n[2];
  auto index = [&](int64_t i, int64_t j, int64_t k) { return i + n[0] * (j + n[1] * k); };
  std::vector<uint8_t> grid(size_t(total), kInside);
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
  // Flood from the border through every cell that is not certainly inside.
  std::vector<int64_t> queue;
  auto push = [&](int64_t i, int64_t j, int64_t k) {
    uint8_t& g = grid[size_t(index(i, j, k))];
    if (g == kInside || (g & kReached)) return;
    g |= kReached;
    queue.push_back(index(i, j, k));
  };
  for (int64_t k = 0; k < n[2]; ++k)
    for (int64_t j = 0; j < n[1]; ++j)
      for (int64_t i = 0; i < n[0]; ++i)
        if (i == 0 || j == 0 || k == 0 || i == n[0] - 1 || j == n[1] - 1 || k == n[2] - 1) push(i, j, k);
  for (size_t q = 0; q < queue.size(); ++q) {
    int64_t id = queue[q];
    int64_t i = id % n[0], j = (id / n[0]) % n[1], k = id / (n[0] * n[1]);
    if (i > 0) push(i - 1, j, k);
    if (i + 1 < n[0]) push(i + 1, j, k);
    if (j > 0) push(i, j - 1, k);
    if (j + 1 < n[1]) push(i, j + 1, k);
    if (k > 0) push(i, j, k - 1);
    if (k + 1 < n[2]) push(i, j, k + 1);
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

NarrowBand build_narrow_band(const TriangleBvh& bvh, const Box3& box, double offset,
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
  // Top level: cells of 2^levels fine cells, about 8 along the longest axis.
  int longest = std::max({band.dims[0], band.dims[1], band.dims[2]});
  int levels = 0;
  while ((longest >> levels) > 8) ++levels;

  std::vector<uint64_t> current;
  int top = 1 << levels;
  for (int k = 0; k * top < band.dims[2]; ++k)
    for (int j = 0; j * top < band.dims[1]; ++j)
      for (int i = 0; i * top < band.dims[0]; ++i) current.push_back(grid_key(i, j, k));
  // Closest soup triangle found for each cell's center, handed to its
  // children as a warm start (TriangleBvh::distance): nearby points mostly
  // share their closest triangle, so the search starts with a tight bound.
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
  // The level-1 cells kept, as the parents of the level-0 candidates
  // (contiguous children [begin, end)): any point p of the parent's box has
  // d(p) <= d(center) + half-diagonal, so its closest triangle lies within
  // that radius of the box and is in the parent's gathered list.
  struct Parent {
    Box3 box;
    double radius;
    size_t begin, end;
  };
  std::vector<Parent> groups;
  // A query answering "hi" for every distance >= hi needs no triangle farther
  // than hi from the box: if the closest one is, every point's answer is hi.
  auto capped = [](double radius, double hi) { return std::min(radius, hi * (1 + 1e-9)); };
  std::vector<uint32_t> group_of;  // per current cell, at level 0
  std::vector<double> distances;   // per current cell: d(center), exact when kept

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
    auto decide = [&](long n, double d) {
      distances[size_t(n)] = d;
      keep[size_t(n)] = d > lo && d < hi;
      labels[size_t(n)] = keep[size_t(n)] ? kBand : d >= hi ? kOutside : kInside;
    };
    if (level == 0 && !groups.empty()) {
      // Level 0 by parent: one candidate list per level-1 cell serves its
      // eight children (nearest-candidate culling instead of a BVH descent
      // from the root for every center).
#pragma omp parallel
      {
        std::vector<uint32_t> list;
#pragma omp for schedule(dynamic, 16)
        for (long g = 0; g < long(groups.size()); ++g) {
          list.clear();
          bvh.gather(groups[size_t(g)].box, capped(groups[size_t(g)].radius, hi), list);
          for (size_t n = groups[size_t(g)].begin; n < groups[size_t(g)].end; ++n)
            decide(long(n), bvh.distance_among(center_of(current[n], size), list, lo, hi, &hint[n]));
        }
      }
    } else {
#pragma omp parallel for schedule(dynamic, 256)
      for (long n = 0; n < long(current.size()); ++n)
        decide(n, bvh.distance(center_of(current[n], size), lo, hi, &hint[n]));
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
          if (!group_of.empty()) group_of[kept] = group_of[n];
          hint[kept++] = hint[n];
        }
      current.resize(kept);
      hint.resize(kept);
      if (!group_of.empty()) group_of.resize(kept);
      break;
    }
    std::vector<uint64_t> next;
    std::vector<uint32_t> next_hint;
    const bool parents = level == 1;
    if (parents) {
      groups.clear();
      group_of.clear();
    }
    for (size_t n = 0; n < current.size(); ++n) {
      if (!keep[n]) continue;
      if (parents)
        groups.push_back({box_of(current[n], size), (distances[n] + half_diagonal) * (1 + 1e-7), next.size(), 0});
      auto c = grid_coords(current[n]);
      for (int dz = 0; dz < 2; ++dz)
        for (int dy = 0; dy < 2; ++dy)
          for (int dx = 0; dx < 2; ++dx) {
            int i = 2 * c[0] + dx, j = 2 * c[1] + dy, k = 2 * c[2] + dz;
            int child_size = 1 << (level - 1);
            if (i * child_size < band.dims[0] && j * child_size < band.dims[1] &&
                k * child_size < band.dims[2])
            {
              next.push_back(grid_key(i, j, k));
              next_hint.push_back(hint[n]);
              if (parents) group_of.push_back(uint32_t(groups.size() - 1));
            }
          }
      if (parents) groups.back().end = next.size();
    }
    current.swap(next);
    hint.swap(next_hint);
  }

  // Corners of the candidate leaves, each with its cell's warm start. A
  // corner of a cell the level set crosses is within sqrt(3) h of it, so a
  // band query of o +- 1.75 h gives exact values wherever they are used
  // (1-Lipschitz); values outside the band only need their sign.
  struct Corner {
    uint64_t key;
    uint32_t hint;
    uint32_t group;  // a parent whose box holds the corner (grouped mode)
  };
  std::vector<Corner> corners;
  corners.reserve(current.size() * 8);
  const bool grouped = !groups.empty();
  for (size_t n = 0; n < current.size(); ++n) {
    auto c = grid_coords(current[n]);
    for (int v = 0; v < 8; ++v)
      corners.push_back({grid_key(c[0] + (v & 1), c[1] + ((v >> 1) & 1), c[2] + (v >> 2)), hint[n],
                         grouped ? group_of[n] : 0});
  }
  std::sort(corners.begin(), corners.end(), [](const Corner& a, const Corner& b) { return a.key < b.key; });
  corners.erase(std::unique(corners.begin(), corners.end(),
                            [](const Corner& a, const Corner& b) { return a.key == b.key; }),
                corners.end());
  band.corner_keys.resize(corners.size());
  for (size_t n = 0; n < corners.size(); ++n) band.corner_keys[n] = corners[n].key;
  band.corner_values.resize(band.corner_keys.size());
  progress.update("proxy: narrow band", double(levels) / (levels + 1));
  const double band_width = 1.75 * cell;  // > sqrt(3) h
  const double corner_lo = offset - band_width, corner_hi = offset + band_width;
  if (grouped) {
    // Corners by parent (counting sort), one gathered list per parent.
    std::vector<size_t> start(groups.size() + 1, 0);
    for (const Corner& c : corners) ++start[c.group + 1];
    for (size_t g = 0; g < groups.size(); ++g) start[g + 1] += start[g];
    std::vector<uint32_t> order(corners.size());
    {
      std::vector<size_t> fill(start.begin(), start.end() - 1);
      for (size_t n = 0; n < corners.size(); ++n) order[fill[corners[n].group]++] = uint32_t(n);
    }
#pragma omp parallel
    {
      std::vector<uint32_t> list;
#pragma omp for schedule(dynamic, 16)
      for (long g = 0; g < long(groups.size()); ++g) {
        if (start[size_t(g)] == start[size_t(g) + 1]) continue;
        list.clear();
        bvh.gather(groups[size_t(g)].box, capped(groups[size_t(g)].radius, corner_hi), list);
        for (size_t m = start[size_t(g)]; m < start[size_t(g) + 1]; ++m) {
          uint32_t n = order[m];
          uint32_t warm = corners[n].hint;
          double d = bvh.distance_among(band.corner_position(corners[n].key), list, corner_lo, corner_hi, &warm);
          band.corner_values[n] = d - offset;
        }
      }
    }
  } else {
#pragma omp parallel for schedule(dynamic, 1024)
    for (long n = 0; n < long(corners.size()); ++n) {
      uint32_t warm = corners[n].hint;
      double d = bvh.distance(band.corner_position(corners[n].key), corner_lo, corner_hi, &warm);
      band.corner_values[n] = d - offset;
    }
  }
  // Leaves: the candidates whose corners change sign; the others hold no
  // surface. Their unused corners stay (harmless, and lookups stay simple).
  std::vector<char> crossing(current.size());
#pragma omp parallel for schedule(static)
  for (long n = 0; n < long(current.size()); ++n) {
    auto c = grid_coords(current[n]);
    int inside = 0;
    for (int v = 0; v < 8; ++v)
      inside += band.value(grid_key(c[0] + (v & 1), c[1] + ((v >> 1) & 1), c[2] + (v >> 2))) < 0;
    crossing[n] = inside != 0 && inside != 8;
  }
  std::vector<uint64_t> leaves;
  for (size_t n = 0; n < current.size(); ++n)
    if (crossing[n]) leaves.push_back(current[n]);
  std::sort(leaves.begin(), leaves.end());
  band.cells = std::move(leaves);
  band.distance_evaluations = evaluations + band.corner_keys.size();
  return band;
}

}  // namespace soupuv::proxy
