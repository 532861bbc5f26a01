#include "atlas/pack.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <climits>

#include "atlas/raster_pack.h"
#include "atlas/turn_chart.h"
#include "soupuv/errors.h"

namespace soupuv::atlas {
namespace {

std::vector<Vec2> convex_hull(std::vector<Vec2> p) {
  std::sort(p.begin(), p.end(), [](Vec2 a, Vec2 b) { return a.x != b.x ? a.x < b.x : a.y < b.y; });
  if (p.size() < 3) return p;
  std::vector<Vec2> h(2 * p.size());
  size_t k = 0;
  for (size_t i = 0; i < p.size(); ++i) {
    while (k >= 2 && cross(h[k - 1] - h[k - 2], p[i] - h[k - 2]) <= 0) --k;
    h[k++] = p[i];
  }
  for (size_t i = p.size() - 1, lower = k + 1; i-- > 0;) {
    while (k >= lower && cross(h[k - 1] - h[k - 2], p[i] - h[k - 2]) <= 0) --k;
    h[k++] = p[i];
  }
  h.resize(k - 1);
  return h;
}

// Rotates the chart so its minimal-area bounding rectangle is axis-aligned and
// moves that rectangle's corner to the origin; returns the rectangle size.
Vec2 align_to_min_rectangle(std::vector<Vec2>& uv) {
  MinRectangle rect = min_area_rectangle(uv);
  // Rotation taking rect.axis to +x keeps orientation (no mirror).
  Vec2 lo{INFINITY, INFINITY}, hi{-INFINITY, -INFINITY};
  for (Vec2& p : uv) {
    p = {dot(p, rect.axis), cross(rect.axis, p)};
    lo = {std::min(lo.x, p.x), std::min(lo.y, p.y)};
    hi = {std::max(hi.x, p.x), std::max(hi.y, p.y)};
  }
  for (Vec2& p : uv) p = p - lo;
  return hi - lo;
}

// A chart turned by one of the base angles and moved to the positive quadrant,
// with its bounding box size: the quarter turns of each pose are tried.
struct Pose {
  std::vector<Vec2> uv;
  Vec2 size;
};

// The chart turned by `angle` (radians, counter-clockwise: no mirror) with its
// bounding box's corner moved to the origin.
Pose make_pose(const std::vector<Vec2>& uv, double angle) {
  TurnedChart t = turn_chart(uv, angle);
  for (Vec2& q : t.uv) q = q - t.lo;
  return {std::move(t.uv), t.hi - t.lo};
}

// Quarter turn r (0..3) of a point in a w x h box, staying in the positive quadrant.
Vec2 turn(Vec2 p, int r, Vec2 size) {
  switch (r) {
    case 1: return {size.y - p.y, p.x};
    case 2: return {size.x - p.x, size.y - p.y};
    case 3: return {p.y, size.x - p.x};
    default: return p;
  }
}

// Lowest and highest texel row the chart covers in each cell column, for the
// chart's local frame (its rectangle's corner at (half, half) texels),
// dilated by `half` texels: the Minkowski sum with a square, so that two
// dilated charts that do not overlap keep 2 * half texels apart.
struct Profile {
  std::vector<double> bottom, top;
};

Profile profile(const std::vector<Vec2>& uv, const std::vector<int>& outline, int r, Vec2 size,
                double scale, double half, double column_width) {
  // The exact y-range is first taken in one-texel strips, then each column
  // takes the strips within `half` of it. A disk's extremes in a strip lie on
  // its boundary, so the outline's segments suffice.
  const double strip = std::min(1.0, column_width);
  Vec2 turned_size = (r % 2) ? Vec2{size.y, size.x} : size;
  const double width = turned_size.x * scale + 2 * half;
  const int strips = static_cast<int>(std::ceil(width / strip)) + 1;
  const int columns = static_cast<int>(std::ceil(width / column_width)) + 1;
  Profile raw{std::vector<double>(strips, INFINITY), std::vector<double>(strips, -INFINITY)};
  auto texel = [&](int v) {
    Vec2 q = turn(uv[v], r, size);
    return Vec2{q.x * scale + half, q.y * scale + half};
  };
  const size_t m = outline.size();
  for (size_t i = 0; i < m; ++i) {
    Vec2 a = texel(outline[i]), b = texel(outline[(i + 1) % m]);
    int c0 = std::max(0, static_cast<int>(std::min(a.x, b.x) / strip));
    int c1 = std::min(strips - 1, static_cast<int>(std::max(a.x, b.x) / strip));
    for (int c = c0; c <= c1; ++c) {
      // y-range of the segment inside the strip: its start if within, and its
      // crossings of the strip's two sides.
      double lo_x = c * strip, hi_x = lo_x + strip;
      auto take = [&](double y) {
        raw.bottom[c] = std::min(raw.bottom[c], y);
        raw.top[c] = std::max(raw.top[c], y);
      };
      if (a.x >= lo_x && a.x <= hi_x) take(a.y);
      if (b.x >= lo_x && b.x <= hi_x) take(b.y);
      for (double x : {lo_x, hi_x})
        if ((a.x - x) * (b.x - x) < 0) take(a.y + (b.y - a.y) * (x - a.x) / (b.x - a.x));
    }
  }
  Profile out{std::vector<double>(columns, INFINITY), std::vector<double>(columns, -INFINITY)};
  for (int c = 0; c < columns; ++c) {
    int d0 = std::max(0, static_cast<int>(std::floor((c * column_width - half) / strip)));
    int d1 = std::min(strips - 1, static_cast<int>(std::ceil(((c + 1) * column_width + half) / strip)) - 1);
    for (int d = d0; d <= d1; ++d) {
      if (!(raw.bottom[d] <= raw.top[d])) continue;
      out.bottom[c] = std::min(out.bottom[c], raw.bottom[d] - half);
      out.top[c] = std::max(out.top[c], raw.top[d] + half);
    }
  }
  return out;
}

struct Placement {
  int pose = 0, rotation = 0, column = 0, row = 0;
};


// Occupancy of a strip of cells, kept per column as signed run lengths:
// run > 0 means that many free cells from here upward, run < 0 that many
// occupied. A chart column needing `len` free cells from row r fits iff
// run >= len, and a misfit tells how far up the next chance lies.
class Occupancy {
 public:
  // Row-major: the placement test reads neighbouring columns at nearby rows.
  Occupancy(int width, int height)
      : width_(width), height_(height), occupied_(static_cast<size_t>(width) * height, 0),
        run_(static_cast<size_t>(width) * height), top_filled_(width, -1) {
    for (int x = 0; x < width; ++x) update(x, height - 1, 0);
  }
  int height() const { return height_; }
  int run(int x, int y) const { return run_[at(x, y)]; }
  void fill(int x, int y0, int y1) {
    for (int y = y0; y <= y1; ++y) occupied_[at(x, y)] = 1;
    // Runs above y1 are unchanged; below y0 only the free run that ended in
    // the filled rows changes.
    update(x, y1, y0);
    top_filled_[x] = std::max(top_filled_[x], y1);
  }
  // Empty again. Only the rows up to a column's highest filled row ever
  // changed: a packing resets what it used, not the whole strip (three
  // squares tall; rebuilding it was most of a few-chart packing).
  void clear() {
    for (int x = 0; x < width_; ++x) {
      for (int y = 0; y <= top_filled_[x]; ++y) {
        occupied_[at(x, y)] = 0;
        run_[at(x, y)] = height_ - y;
      }
      top_filled_[x] = -1;
    }
  }

 private:
  size_t at(int x, int y) const { return static_cast<size_t>(y) * width_ + x; }
  // Recomputes column x from row `top` down, past `floor`, until an occupied row.
  void update(int x, int top, int floor) {
    for (int y = top; y >= 0; --y) {
      bool occ = occupied_[at(x, y)];
      if (y < floor && occ) break;
      bool next_same = y + 1 < height_ && (occupied_[at(x, y + 1)] != 0) == occ;
      int above = next_same ? run_[at(x, y + 1)] : 0;
      run_[at(x, y)] = occ ? above - 1 : above + 1;
    }
  }
  int width_, height_;
  std::vector<char> occupied_;
  std::vector<int> run_;
  std::vector<int> top_filled_;  // per column: the highest row filled, -1 if none
};

// A chart turned and scaled, as one run of cells per column.
struct CellShape {
  std::vector<int> lo, hi;  // inclusive rows; lo > hi for an empty column
  int height = 0;
};

CellShape cell_shape(const Profile& p, double row_height) {
  CellShape s;
  const int w = static_cast<int>(p.bottom.size());
  s.lo.assign(w, 1);
  s.hi.assign(w, 0);
  for (int c = 0; c < w; ++c) {
    if (!(p.bottom[c] <= p.top[c])) continue;
    s.lo[c] = std::max(0, static_cast<int>(std::floor(p.bottom[c] / row_height)));
    s.hi[c] = std::max(s.lo[c], static_cast<int>(std::ceil(p.top[c] / row_height)) - 1);
    s.height = std::max(s.height, s.hi[c] + 1);
  }
  return s;
}

// Lowest row at which the shape fits with its left column at x, or -1 when
// its top would pass `top_limit` first. `hint` is the column that blocked
// last time: neighbouring x usually hit the same obstacle, so testing it
// first rejects most rows at once.
int lowest_fit(const Occupancy& occ, const CellShape& s, int x, int top_limit, int& hint) {
  const int w = static_cast<int>(s.lo.size());
  const int n = occ.height();
  int y = 0;
  while (y + s.height <= std::min(n, top_limit)) {
    int next = y;
    for (int i = 0; i < w && next == y; ++i) {
      int c = (hint + i) % w;
      if (s.lo[c] > s.hi[c]) continue;
      int r = y + s.lo[c], len = s.hi[c] - s.lo[c] + 1;
      int v = occ.run(x + c, r);
      if (v >= len) continue;
      // Skip past the occupied run that blocks this column.
      next = v > 0 ? (r + v < n ? y + v - occ.run(x + c, r + v) : n) : y - v;
      hint = c;
    }
    if (next == y) return y;
    y = next;
  }
  return -1;
}

// The packing grid: columns a few texels wide (placement work grows with
// their number), rows one texel tall (run lengths make height cheap).
struct Grid {
  int columns, rows;           // per side of the square
  double column_width, row_height;  // in texels
};

// One greedy variant: the order charts are placed in, how many of the
// chart's poses are tried (each in four quarter turns), and what "lowest"
// means: the position minimising bottom row + height_weight * chart height (1:
// lowest top, skyline packing; below 1 leans towards bottom-left fill).
struct Heuristic {
  const std::vector<int>* order;
  int poses;
  double height_weight;
};

// One packing at `scale` texels per UV unit into a strip one square wide and
// three tall (`occ`, emptied first); returns the rows used (more than grid.rows overflows the
// square), or INT_MAX if a chart is wider than the strip.
int pack_at(const std::vector<PackChart>& charts, const std::vector<std::vector<Pose>>& poses,
            const Heuristic& heuristic, double scale, double padding, const Grid& grid, Occupancy& occ,
            std::vector<Placement>& placements) {
  const double half = 0.5 * padding;
  occ.clear();
  placements.assign(charts.size(), {});
  int used = 0;
  for (int ci : *heuristic.order) {
    // Every pose in four quarter turns keeps its lowest-top position; the
    // lowest of those wins.
    int best_top = INT_MAX;
    double best_score = INFINITY;
    Placement best;
    CellShape best_shape;
    for (int v = 0; v < heuristic.poses; ++v)
      for (int r = 0; r < 4; ++r) {
        const Pose& pose = poses[ci][v];
        CellShape shape = cell_shape(
            profile(pose.uv, *charts[ci].outline, r, pose.size, scale, half, grid.column_width),
            grid.row_height);
        const int w = static_cast<int>(shape.lo.size());
        int hint = 0;
        bool better = false;
        for (int x = 0; x + w <= grid.columns; ++x) {
          int limit = std::isinf(best_score) ? occ.height() : static_cast<int>(best_score - heuristic.height_weight * shape.height) + shape.height;
          int y = lowest_fit(occ, shape, x, limit, hint);
          if (y < 0) continue;
          double score = y + heuristic.height_weight * shape.height;
          if (score >= best_score) continue;
          best_score = score;
          best_top = y + shape.height;
          best = {v, r, x, y};
          better = true;
        }
        if (better) best_shape = std::move(shape);
      }
    if (best_top == INT_MAX) return INT_MAX;
    for (size_t c = 0; c < best_shape.lo.size(); ++c)
      if (best_shape.lo[c] <= best_shape.hi[c])
        occ.fill(best.column + static_cast<int>(c), best.row + best_shape.lo[c],
                 best.row + best_shape.hi[c]);
    placements[ci] = best;
    used = std::max(used, best_top);
  }
  return used;
}

}  // namespace

MinRectangle min_area_rectangle(const std::vector<Vec2>& points) {
  std::vector<Vec2> hull = convex_hull(points);
  MinRectangle best{{1, 0}, {0, 0}};
  double best_area = INFINITY;
  for (size_t i = 0; i < hull.size(); ++i) {
    Vec2 e = hull[(i + 1) % hull.size()] - hull[i];
    double len = norm(e);
    if (len <= 0) continue;
    Vec2 d = e * (1 / len);
    double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
    for (Vec2 p : hull) {
      double x = dot(p, d), y = cross(d, p);
      x0 = std::min(x0, x); x1 = std::max(x1, x);
      y0 = std::min(y0, y); y1 = std::max(y1, y);
    }
    if ((x1 - x0) * (y1 - y0) < best_area) {
      best_area = (x1 - x0) * (y1 - y0);
      best = {d, {x1 - x0, y1 - y0}};
    }
  }
  return best;
}

PackResult pack_charts(std::vector<PackChart>& charts, int texture_size, double padding_px,
                       const RasterPackOptions& raster_options) {
  PackResult result;
  const int n = static_cast<int>(charts.size());
  std::vector<Vec2> sizes(n);
  std::vector<std::vector<Pose>> poses(n);
  // Poses: the minimal-rectangle alignment, then turned by 30 and 60 degrees.
  const int pose_count = 3;
  double area = 0;
  for (int i = 0; i < n; ++i) {
    sizes[i] = align_to_min_rectangle(*charts[i].uv);
    for (int v = 0; v < pose_count; ++v)
      poses[i].push_back(make_pose(*charts[i].uv, v * 0.5 * M_PI / pose_count));
    for (const auto& t : *charts[i].triangles) {
      const auto& uv = *charts[i].uv;
      area += 0.5 * std::fabs(cross(uv[t[1]] - uv[t[0]], uv[t[2]] - uv[t[0]]));
    }
  }
  Grid grid;
  grid.columns = std::max(16, std::min(texture_size, 2048) / 4);
  grid.rows = std::min(texture_size, 4096);
  grid.column_width = static_cast<double>(texture_size) / grid.columns;
  grid.row_height = static_cast<double>(texture_size) / grid.rows;

  // Scale search: pack into a tall strip, then rescale by sqrt(square height /
  // used height) — a few packings instead of a blind bisection. `lo` is the
  // largest scale seen to fit, `hi` the smallest seen to overflow.
  std::vector<Placement> placements, best_placements;
  Occupancy occ(grid.columns, 3 * grid.rows);
  const double full = texture_size / std::sqrt(std::max(area, 1e-300));  // 100% utilisation
  double lo = 0;
  double precision = 1.005;  // scale bracket width at which a search stops
  auto search = [&](const Heuristic& heuristic, double start, double lo_known) {
    double hi = full, s = start, found = lo_known;
    for (int it = 0; it < 40 && (found == 0 || hi / found > precision); ++it) {
      ++result.attempts;
      int used = pack_at(charts, poses, heuristic, s, padding_px, grid, occ, placements);
      if (used <= grid.rows) {
        found = s;
        lo = std::max(lo, s);
        best_placements = placements;
      } else {
        hi = std::min(hi, s);
        // A second order only matters if it beats the first one.
        if (lo_known > 0 && s <= lo_known * (precision + 1e-4)) break;
      }
      double guess = used == INT_MAX ? 0.5 * s : s * std::sqrt(static_cast<double>(grid.rows) / used);
      if (used > grid.rows) guess *= 0.995;
      // Stay strictly inside the bracket; fall back to its middle.
      if (!(guess > found && guess < hi)) guess = found > 0 ? std::sqrt(found * hi) : 0.5 * s;
      if (found == 0 && guess < full * 1e-9) break;
      s = guess;
    }
  };
  // Two orders: largest area first and longest side first.
  std::vector<int> by_area(n);
  std::iota(by_area.begin(), by_area.end(), 0);
  std::vector<int> by_side = by_area;
  std::stable_sort(by_area.begin(), by_area.end(), [&](int a, int b) {
    return sizes[a].x * sizes[a].y > sizes[b].x * sizes[b].y;
  });
  std::stable_sort(by_side.begin(), by_side.end(), [&](int a, int b) {
    return std::max(sizes[a].x, sizes[a].y) > std::max(sizes[b].x, sizes[b].y);
  });
  // A portfolio of greedy variants: each is cheap, none wins everywhere
  // (measured spread about 1% of utilisation either way per mesh), and every
  // variant after the first costs one or two packings since it only has to beat
  // the scale found so far.
  std::vector<Heuristic> variants = {
      {&by_area, 1, 1.0}, {&by_side, 1, 1.0}, {&by_area, 1, 0.5}, {&by_side, 1, 0.5}, {&by_area, 1, 0.75}};
  // Turned poses cost three times as much per packing; with few charts they
  // are cheap and were measured to pay (sphere 5k: 0.690 -> 0.704).
  if (n <= 64) variants.insert(variants.end(), {{&by_area, 3, 1.0}, {&by_area, 3, 0.5}});
  auto raster_layout = [&](const RasterPackResult& raster) {
    result.method = "raster";
    result.uv_per_length = raster.scale / texture_size;
    result.utilization = 0;
    for (int i = 0; i < n; ++i)
      for (const auto& t : *charts[i].triangles) {
        const auto& uv = *charts[i].uv;
        result.utilization += 0.5 * std::fabs(cross(uv[t[1]] - uv[t[0]], uv[t[2]] - uv[t[0]]));
      }
    return result;
  };
  // Many charts: the bitmap packer alone, from its own scale guess; it beat
  // the column portfolio on every mesh with more than 64 charts measured
  // (torus 5k 0.701 -> 0.718, genus 3 12k 0.701 -> 0.711, drilled block
  // 0.804 -> 0.820), and the portfolio's packings cost about as much again.
  // The columns remain the fallback if it finds no layout at all.
  const bool raster_only = raster_options.angles > 0 && n > 64;
  if (raster_only) {
    RasterPackResult raster = raster_pack(charts, texture_size, padding_px, 0, raster_options);
    result.attempts += raster.attempts;
    if (raster.scale > 0) return raster_layout(raster);
  }
  size_t winner = 0;
  for (size_t v = 0; v < variants.size(); ++v) {
    double before = lo;
    if (v == 0) search(variants[v], full * std::sqrt(0.8), 0);
    else if (lo > 0) search(variants[v], lo * 1.01, lo);
    if (lo > before) winner = v;
  }
  // The bitmap packer interlocks charts the column packer cannot (it sees
  // every texel row, not one run per 4-texel column) and turns them freely;
  // its layout (written into the UVs at once) counts only if it fits a
  // larger scale.
  RasterPackResult raster;
  if (!raster_only) raster = raster_pack(charts, texture_size, padding_px, lo, raster_options);
  result.attempts += raster.attempts;
  if (raster.scale > 0) lo = raster.scale;
  // Second pass, only when both end below 70% utilisation: the winning
  // column variant again with the 30/60-degree poses (three times the work
  // per packing, hence skipped for many charts above) and a finer scale
  // search. Measured on genus 3, 12k faces: 0.690 -> 0.701 for 1.9 -> 2.3 s
  // CPU (before the bitmap packer existed).
  auto utilisation_at = [&](double s) { return area * s * s / (static_cast<double>(texture_size) * texture_size); };
  if (lo > 0 && utilisation_at(lo) < 0.70) {
    precision = 1.002;
    Heuristic turned = variants[winner];
    turned.poses = pose_count;
    search(turned, lo * 1.008, lo);
  }
  if (raster.scale > 0 && lo == raster.scale) return raster_layout(raster);
  if (lo == 0)
    throw Error(ErrorCode::limit_exceeded,
                "atlas: " + std::to_string(n) + " charts do not fit a " +
                    std::to_string(texture_size) + " texture with " +
                    std::to_string(padding_px) + " px padding");

  const double half = 0.5 * padding_px;
  double uv_area = 0;
  for (int i = 0; i < n; ++i) {
    const Placement& p = best_placements[i];
    const Pose& pose = poses[i][p.pose];
    for (size_t k = 0; k < pose.uv.size(); ++k) {
      Vec2& q = (*charts[i].uv)[k];
      Vec2 t = turn(pose.uv[k], p.rotation, pose.size);
      q = {(p.column * grid.column_width + t.x * lo + half) / texture_size,
           (p.row * grid.row_height + t.y * lo + half) / texture_size};
    }
    for (const auto& t : *charts[i].triangles) {
      const auto& uv = *charts[i].uv;
      uv_area += 0.5 * std::fabs(cross(uv[t[1]] - uv[t[0]], uv[t[2]] - uv[t[0]]));
    }
  }
  result.method = "columns";
  result.uv_per_length = lo / texture_size;
  result.utilization = uv_area;
  return result;
}

}  // namespace soupuv::atlas
