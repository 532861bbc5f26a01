#include "uvsolve/pack_islands.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "atlas/pack.h"
#include "atlas/raster_pack.h"
#include "uvsolve/nest_rows.h"
#include "soupuv/errors.h"

namespace soupuv::uvsolve::detail {
namespace {

// Islands the bitmap packer places one by one when there are many; the
// rest go in rows first (docs/tuning.md: 2,048 against 512 and 1,024,
// measured with the packer's turns on both threads).
constexpr size_t kPackedAlone = 2048;

// The raster the islands are packed on: the texture's, up to this many
// texels a side. The packer's first-fit search grows faster than the
// raster's texels (40x from 1024 to 4096 on ogre, docs/tuning.md); a
// coarser raster with the padding in its own texels, rounded up, keeps
// every gap at least the texture's padding.
constexpr int kMaxPackRaster = 2048;

// Maps of at most kFewUnits pieces are packed once per turn count in
// kFewUnitTurns, the densest kept: a packing of so few pieces costs
// 0.04-0.15 s (docs/tuning.md); at 8 pieces the three packings added up to
// 0.7 s to a map whose halving packs it several times.
constexpr size_t kFewUnits = 4;
constexpr int kFewUnitTurns[] = {16, 24, 32};

// What the bitmap packer moves as one piece: one island, or a row-packed
// group of small ones (local vertices, triangles, boundary edges).
struct Unit {
  std::vector<Vec2> uv;
  std::vector<std::array<int, 3>> tris;
  std::vector<std::array<int, 2>> boundary;
};

// Small islands packed as one unit: rows of islands nested side by side
// (nest_rows.h), each island's vertices and triangles a range of the
// unit's, moved by `shift` from the island's own frame (its box's corner at
// the origin).
struct GroupMember {
  Vec2 size;
  uint32_t first, count;
  uint32_t first_tri, tri_count;
  Vec2 shift;
};
struct Group {
  uint32_t unit;
  std::vector<std::vector<GroupMember>> rows;
};

// A member's triangles in its own frame.
void member_triangles(const Unit& unit, const GroupMember& m, std::vector<RowTriangle>& out) {
  out.clear();
  for (uint32_t t = m.first_tri; t < m.first_tri + m.tri_count; ++t) {
    const auto& tri = unit.tris[t];
    out.push_back({unit.uv[tri[0]] - m.shift, unit.uv[tri[1]] - m.shift, unit.uv[tri[2]] - m.shift});
  }
}

// Lays out a group's rows `gap` apart, its islands nested `gap` apart in
// a row (nest_rows.h). Rows are not nested into each other: the islands
// lie with a flat side along the row's bottom or top, so a row's top and
// the next one's bottom are mostly flat against flat (docs/tuning.md).
void lay_out_rows(Group& g, double gap, std::vector<Unit>& units) {
  Unit& unit = units[g.unit];
  std::vector<RowTriangle> tris;
  double y = 0;
  for (auto& row : g.rows) {
    RowNester nest(gap);
    double row_height = 0;
    for (GroupMember& m : row) {
      member_triangles(unit, m, tris);
      const double x = nest.shift_for(tris.data(), tris.size());
      nest.add(tris.data(), tris.size(), m.size.x, x);
      const Vec2 shift{x, y};
      for (uint32_t v = m.first; v < m.first + m.count; ++v) unit.uv[v] = unit.uv[v] - m.shift + shift;
      m.shift = shift;
      row_height = std::max(row_height, m.size.y);
    }
    y += row_height + gap;
  }
}

// Appends island `tris` of the layout to `unit`, its vertices moved by
// `shift`; records where each corner's vertex went.
// Turned by `axis` (a unit vector that becomes +x) first, when given.
void append_island(const UvLayout& L, const std::vector<uint32_t>& tris, Vec2 shift, Unit& unit,
                   std::vector<uint32_t>& local, std::vector<std::array<int, 3>>& corner_slot,
                   Vec2 axis = {1, 0}) {
  const int base_tri = int(unit.tris.size());
  for (uint32_t t : tris) {
    std::array<int, 3> tri;
    for (int c = 0; c < 3; ++c) {
      const uint32_t v = L.corner_vertex[t][c];
      if (local[v] == UINT32_MAX) {
        local[v] = uint32_t(unit.uv.size());
        const Vec2 p = L.uv[v];
        unit.uv.push_back(Vec2{axis.x * p.x + axis.y * p.y, -axis.y * p.x + axis.x * p.y} + shift);
      }
      tri[c] = int(local[v]);
    }
    unit.tris.push_back(tri);
    corner_slot[t] = tri;
  }
  // Boundary edges: an edge used an odd number of times (even-odd rule).
  std::vector<std::pair<uint64_t, std::array<int, 2>>> edges;
  for (size_t j = base_tri; j < unit.tris.size(); ++j)
    for (int c = 0; c < 3; ++c) {
      const int a = unit.tris[j][c], b = unit.tris[j][(c + 1) % 3];
      edges.push_back({(uint64_t(std::min(a, b)) << 32) | uint32_t(std::max(a, b)), {a, b}});
    }
  std::sort(edges.begin(), edges.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
  for (size_t e = 0; e < edges.size();) {
    size_t f = e;
    while (f < edges.size() && edges[f].first == edges[e].first) ++f;
    if ((f - e) % 2 == 1) unit.boundary.push_back(edges[e].second);
    e = f;
  }
  for (uint32_t t : tris)
    for (int c = 0; c < 3; ++c) local[L.corner_vertex[t][c]] = UINT32_MAX;
}

}  // namespace

PackFigures pack_islands(const UvLayout& L, int texture_size, double padding_px, int threads,
                         std::vector<std::array<Vec2, 3>>& corner_uvs, PackEffort effort) {
  const int raster = std::min(texture_size, kMaxPackRaster);
  const double raster_padding = padding_px * raster / texture_size;
  const auto islands = island_triangles(L);
  const size_t k = islands.size();
  std::vector<Vec2> lo(k, {INFINITY, INFINITY}), hi(k, {-INFINITY, -INFINITY});
  double total_area = 0;
  for (size_t i = 0; i < k; ++i)
    for (uint32_t t : islands[i]) {
      total_area += 0.5 * std::abs(signed_area2(L, t));
      for (uint32_t v : L.corner_vertex[t]) {
        lo[i] = {std::min(lo[i].x, L.uv[v].x), std::min(lo[i].y, L.uv[v].y)};
        hi[i] = {std::max(hi[i].x, L.uv[v].x), std::max(hi[i].y, L.uv[v].y)};
      }
    }
  // Grouped islands are kept the padding apart at every trial scale (the
  // rows are laid out again per packing, below); the rows are filled with
  // the gap of the largest scale, the one that fills the square.
  const double max_scale = total_area > 0 ? raster / std::sqrt(total_area) : 1;
  const double fill_gap = raster_padding / max_scale;
  // When there are many islands, all but the kPackedAlone largest (each costs the
  // packer a rasterisation per turn and a search per packing, whatever its
  // size) are grouped into rows about 1/8 of the square's side wide before
  // packing; an island longer than half a row stays alone.
  const double row_width = std::sqrt(total_area) / 8;
  std::vector<uint8_t> small(k, 0);
  if (k > 2 * kPackedAlone) {
    std::vector<double> area(k, 0);
    for (size_t i = 0; i < k; ++i)
      for (uint32_t t : islands[i]) area[i] += std::abs(signed_area2(L, t));
    std::vector<uint32_t> by_area(k);
    std::iota(by_area.begin(), by_area.end(), 0u);
    std::stable_sort(by_area.begin(), by_area.end(), [&](uint32_t a, uint32_t b) { return area[a] > area[b]; });
    for (size_t j = kPackedAlone; j < k; ++j) {
      const uint32_t i = by_area[j];
      small[i] = std::max(hi[i].x - lo[i].x, hi[i].y - lo[i].y) < 0.5 * row_width;
    }
  }

  // Small islands are turned to their minimal-area rectangle, long side
  // along the row (a needle lies flat), before they are put in rows.
  std::vector<Vec2> axis(k, {1, 0});
  for (size_t i = 0; i < k; ++i) {
    if (!small[i]) continue;
    std::vector<Vec2> points;
    for (uint32_t t : islands[i])
      for (uint32_t v : L.corner_vertex[t]) points.push_back(L.uv[v]);
    const atlas::MinRectangle r = atlas::min_area_rectangle(points);
    axis[i] = r.size.x >= r.size.y ? r.axis : Vec2{-r.axis.y, r.axis.x};
    lo[i] = {INFINITY, INFINITY};
    hi[i] = {-INFINITY, -INFINITY};
    for (const Vec2& p : points) {
      const Vec2 q{axis[i].x * p.x + axis[i].y * p.y, -axis[i].y * p.x + axis[i].x * p.y};
      lo[i] = {std::min(lo[i].x, q.x), std::min(lo[i].y, q.y)};
      hi[i] = {std::max(hi[i].x, q.x), std::max(hi[i].y, q.y)};
    }
  }

  std::vector<Unit> units;
  std::vector<uint32_t> local(L.uv.size(), UINT32_MAX);
  std::vector<std::array<int, 3>> corner_slot(L.corner_vertex.size());
  std::vector<uint32_t> unit_of_triangle(L.corner_vertex.size());
  for (size_t i = 0; i < k; ++i) {
    if (small[i]) continue;
    units.emplace_back();
    append_island(L, islands[i], {0, 0}, units.back(), local, corner_slot);
    for (uint32_t t : islands[i]) unit_of_triangle[t] = uint32_t(units.size() - 1);
  }
  // Shelves of small islands, tallest first; a group closes at 8 rows.
  std::vector<uint32_t> order;
  for (size_t i = 0; i < k; ++i)
    if (small[i]) order.push_back(uint32_t(i));
  std::stable_sort(order.begin(), order.end(),
                   [&](uint32_t a, uint32_t b) { return hi[a].y - lo[a].y > hi[b].y - lo[b].y; });
  size_t grouped = 0;
  std::vector<Group> groups;
  std::vector<RowTriangle> tris, turned;
  for (size_t at = 0; at < order.size();) {
    units.emplace_back();
    Unit& unit = units.back();
    groups.push_back({uint32_t(units.size() - 1), {}});
    for (int row = 0; row < 8 && at < order.size(); ++row) {
      groups.back().rows.emplace_back();
      RowNester nest(fill_gap);
      while (at < order.size()) {
        const uint32_t i = order[at];
        const Vec2 size = hi[i] - lo[i];
        const uint32_t first = uint32_t(unit.uv.size()), first_tri = uint32_t(unit.tris.size());
        const size_t first_boundary = unit.boundary.size();
        append_island(L, islands[i], -1.0 * lo[i], unit, local, corner_slot, axis[i]);
        GroupMember m{size, first, uint32_t(unit.uv.size() - first), first_tri,
                      uint32_t(unit.tris.size() - first_tri), Vec2{0, 0}};
        // As it is, or turned by 180 degrees within its box where that
        // nests closer to the island before it.
        member_triangles(unit, m, tris);
        turned = tris;
        for (RowTriangle& t : turned)
          for (Vec2& p : t) p = size - p;
        double x = nest.shift_for(tris.data(), tris.size());
        const double x_turned = nest.shift_for(turned.data(), turned.size());
        const bool turn = x_turned < x;
        if (turn) {
          x = x_turned;
          for (uint32_t v = first; v < first + m.count; ++v) unit.uv[v] = size - unit.uv[v];
          tris.swap(turned);
        }
        if (x > 0 && x + size.x > row_width) {
          // The row is full: the island opens the next (or the next group).
          unit.uv.resize(first);
          unit.tris.resize(first_tri);
          unit.boundary.resize(first_boundary);
          break;
        }
        nest.add(tris.data(), tris.size(), size.x, x);
        groups.back().rows.back().push_back(m);
        for (uint32_t t : islands[i]) unit_of_triangle[t] = uint32_t(units.size() - 1);
        ++at;
        ++grouped;
      }
    }
    lay_out_rows(groups.back(), fill_gap, units);
  }

  std::vector<atlas::PackChart> charts(units.size());
  for (size_t u = 0; u < units.size(); ++u) charts[u] = {&units[u].uv, &units[u].tris, nullptr, &units[u].boundary};
  atlas::RasterPackOptions ro;
  ro.threads = threads;
  std::vector<uint8_t> elastic(units.size(), 0);
  for (const Group& g : groups) elastic[g.unit] = 1;
  if (!groups.empty()) {
    ro.elastic = &elastic;
    ro.at_scale = [&](double scale) {
      for (Group& g : groups) lay_out_rows(g, raster_padding / scale, units);
    };
  }
  // Many units: eight turns, the scale search stopping within 1 % after at
  // most four packings, no further greedy variant (each packing rasterises
  // every unit in every turn; the time goes to packing more islands alone
  // instead, which gains more), and the largest units placed by the pilot
  // rule, since with one greedy order the way they stack decided the
  // utilisation by chance (enclosure 0.575-0.731 over four seeds). Units
  // below 0.1 % of the area try two turns, their minimal-area rectangle
  // lying and standing: the first fit of the many small ones in the holes
  // left was most of the pack's time (table: 62 % of its CPU), and their
  // other turns gained little (table's utilisation -0.01 to -0.02, the
  // other soups' unchanged). Fewer units keep the packer's turns and greedy
  // variants, which hold utilisation on few-island maps, but their scale
  // search too stops within 1 % (of the scale; 2 % of the area): its
  // last bisections cost 0.1-0.2 s a map and gained 0-1 % of the area
  // (docs/tuning.md, session 33). Maps of at most kFewUnits pieces keep the
  // full search (their portfolio below).
  // The thorough effort packs a few pieces the same way: the pilot rule
  // is what it is for, and at 16 turns, nine packings and the greedy
  // variants it cost up to 5 s a map (CesiumMan) for the same gain.
  if (units.size() > kThoroughMaxUnits || effort == PackEffort::thorough) {
    ro.angles = 8;
    ro.precision = 1.01;
    ro.max_packings = 4;
    ro.variant_packings = 0;
    ro.pilot_charts = 8;
    ro.small_chart_share = 0.001;
    ro.small_chart_angles = 2;
  } else if (units.size() > kFewUnits) {
    ro.precision = 1.01;
  }

  // Few units: the packing is a greedy whose outcome turns on small
  // differences (the corpus's boxes, three pieces: 0.548 of the square at
  // 16 turns, 0.571 at 24, 0.586 at 32), and each packing costs little, so
  // it is tried at kFewUnitTurns turns each and the densest kept.
  atlas::RasterPackResult r;
  if (units.size() <= kFewUnits) {
    std::vector<std::vector<Vec2>> start(units.size()), best;
    for (size_t u = 0; u < units.size(); ++u) start[u] = units[u].uv;
    for (const int turns : kFewUnitTurns) {
      for (size_t u = 0; u < units.size(); ++u) units[u].uv = start[u];
      ro.angles = turns;
      const atlas::RasterPackResult trial = atlas::raster_pack(charts, raster, raster_padding, 0, ro);
      if (trial.scale > r.scale) {
        r.scale = trial.scale;
        best.resize(units.size());
        for (size_t u = 0; u < units.size(); ++u) best[u] = units[u].uv;
      }
      r.attempts += trial.attempts;
    }
    if (r.scale > 0)
      for (size_t u = 0; u < units.size(); ++u) units[u].uv = best[u];
  } else {
    r = atlas::raster_pack(charts, raster, raster_padding, 0, ro);
  }
  if (!(r.scale > 0))
    throw Error(ErrorCode::limit_exceeded,
                std::to_string(k) + " UV islands do not fit a " + std::to_string(texture_size) +
                    " texture with " + std::to_string(padding_px) + " texels of padding");
  PackFigures f;
  f.texels_per_uv = r.scale * texture_size / raster;
  f.attempts = r.attempts;
  f.units = units.size();
  f.grouped_islands = grouped;
  corner_uvs.assign(L.corner_vertex.size(), {});
  for (size_t t = 0; t < corner_uvs.size(); ++t) {
    const Unit& unit = units[unit_of_triangle[t]];
    for (int c = 0; c < 3; ++c) corner_uvs[t][c] = unit.uv[corner_slot[t][c]];
    const auto& p = corner_uvs[t];
    f.utilisation += 0.5 * std::abs(cross(p[1] - p[0], p[2] - p[0]));
  }
  return f;
}

}  // namespace soupuv::uvsolve::detail
