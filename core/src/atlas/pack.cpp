#include "atlas/pack.h"

#include <algorithm>
#include <cmath>
#include <numeric>

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
  std::vector<Vec2> hull = convex_hull(uv);
  double best_area = INFINITY;
  Vec2 best_dir{1, 0};
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
    if ((x1 - x0) * (y1 - y0) < best_area) { best_area = (x1 - x0) * (y1 - y0); best_dir = d; }
  }
  // Rotation taking best_dir to +x keeps orientation (no mirror).
  Vec2 lo{INFINITY, INFINITY}, hi{-INFINITY, -INFINITY};
  for (Vec2& p : uv) {
    p = {dot(p, best_dir), cross(best_dir, p)};
    lo = {std::min(lo.x, p.x), std::min(lo.y, p.y)};
    hi = {std::max(hi.x, p.x), std::max(hi.y, p.y)};
  }
  for (Vec2& p : uv) p = p - lo;
  return hi - lo;
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

// Lowest and highest texel row the chart covers in each texel column, padding
// included, for the chart's local frame (corner at (half, half) texels).
struct Profile {
  std::vector<double> bottom, top;
};

Profile profile(const std::vector<Vec2>& uv, const std::vector<std::array<int, 3>>& tri, int r,
                Vec2 size, double scale, double half, double column_width) {
  Vec2 turned_size = (r % 2) ? Vec2{size.y, size.x} : size;
  int columns = static_cast<int>(std::ceil((turned_size.x * scale + 2 * half) / column_width)) + 1;
  Profile raw{std::vector<double>(columns, INFINITY), std::vector<double>(columns, -INFINITY)};
  for (const auto& t : tri) {
    Vec2 p[3];
    for (int k = 0; k < 3; ++k) {
      Vec2 q = turn(uv[t[k]], r, size);
      p[k] = {q.x * scale + half, q.y * scale + half};
    }
    double x0 = std::min({p[0].x, p[1].x, p[2].x}), x1 = std::max({p[0].x, p[1].x, p[2].x});
    int c0 = static_cast<int>(x0 / column_width), c1 = std::min(columns - 1, static_cast<int>(x1 / column_width));
    for (int c = c0; c <= c1; ++c) {
      // y-range of the triangle inside the column's strip: vertices within it
      // and edge crossings of its two sides.
      double lo_x = c * column_width, hi_x = lo_x + column_width;
      double y_lo = INFINITY, y_hi = -INFINITY;
      auto take = [&](double y) { y_lo = std::min(y_lo, y); y_hi = std::max(y_hi, y); };
      for (int k = 0; k < 3; ++k) {
        Vec2 a = p[k], b = p[(k + 1) % 3];
        if (a.x >= lo_x && a.x <= hi_x) take(a.y);
        for (double x : {lo_x, hi_x})
          if ((a.x - x) * (b.x - x) < 0) take(a.y + (b.y - a.y) * (x - a.x) / (b.x - a.x));
      }
      if (y_lo <= y_hi) {
        raw.bottom[c] = std::min(raw.bottom[c], y_lo);
        raw.top[c] = std::max(raw.top[c], y_hi);
      }
    }
  }
  // Dilate by half the padding: two charts then keep a full padding apart.
  int reach = static_cast<int>(std::ceil(half / column_width));
  Profile out{std::vector<double>(columns, INFINITY), std::vector<double>(columns, -INFINITY)};
  for (int c = 0; c < columns; ++c) {
    if (!(raw.bottom[c] <= raw.top[c])) continue;
    for (int d = std::max(0, c - reach); d <= std::min(columns - 1, c + reach); ++d) {
      out.bottom[d] = std::min(out.bottom[d], raw.bottom[c] - half);
      out.top[d] = std::max(out.top[d], raw.top[c] + half);
    }
  }
  return out;
}

struct Placement {
  int rotation = 0, column = 0, row = 0;
};

// Occupancy of the square in cells, kept per column as signed run lengths:
// run > 0 means that many free cells from here upward, run < 0 that many
// occupied. A chart column needing `len` free cells from row r fits iff
// run >= len, and a misfit tells how far up the next chance lies.
class Occupancy {
 public:
  explicit Occupancy(int n) : n_(n), occupied_(static_cast<size_t>(n) * n, 0), run_(static_cast<size_t>(n) * n) {
    for (int x = 0; x < n; ++x) recompute(x);
  }
  int run(int x, int y) const { return run_[static_cast<size_t>(x) * n_ + y]; }
  void fill(int x, int y0, int y1) {
    for (int y = y0; y <= y1; ++y) occupied_[static_cast<size_t>(x) * n_ + y] = 1;
    recompute(x);
  }

 private:
  void recompute(int x) {
    int* r = &run_[static_cast<size_t>(x) * n_];
    const char* o = &occupied_[static_cast<size_t>(x) * n_];
    for (int y = n_ - 1; y >= 0; --y) {
      bool next_same = y + 1 < n_ && (o[y + 1] != 0) == (o[y] != 0);
      r[y] = o[y] ? (next_same ? r[y + 1] - 1 : -1) : (next_same ? r[y + 1] + 1 : 1);
    }
  }
  int n_;
  std::vector<char> occupied_;
  std::vector<int> run_;
};

// A chart turned and scaled, as one run of cells per column.
struct CellShape {
  std::vector<int> lo, hi;  // inclusive rows; lo > hi for an empty column
  int height = 0;
};

CellShape cell_shape(const Profile& p, double cell) {
  CellShape s;
  const int w = static_cast<int>(p.bottom.size());
  s.lo.assign(w, 1);
  s.hi.assign(w, 0);
  for (int c = 0; c < w; ++c) {
    if (!(p.bottom[c] <= p.top[c])) continue;
    s.lo[c] = std::max(0, static_cast<int>(std::floor(p.bottom[c] / cell)));
    s.hi[c] = static_cast<int>(std::floor(p.top[c] / cell));
    s.height = std::max(s.height, s.hi[c] + 1);
  }
  return s;
}

// Lowest row at which the shape fits with its left column at x, or -1; gives
// up once the shape's top would reach `top_limit`.
int lowest_fit(const Occupancy& occ, const CellShape& s, int x, int n, int top_limit) {
  const int w = static_cast<int>(s.lo.size());
  int y = 0;
  while (y + s.height <= std::min(n, top_limit)) {
    int next = y;
    for (int c = 0; c < w && next == y; ++c) {
      if (s.lo[c] > s.hi[c]) continue;
      int r = y + s.lo[c], len = s.hi[c] - s.lo[c] + 1;
      int v = occ.run(x + c, r);
      if (v >= len) continue;
      // Skip past the occupied run that blocks this column.
      next = v > 0 ? (r + v < n ? y + v - occ.run(x + c, r + v) : n) : y - v;
    }
    if (next == y) return y;
    y = next;
  }
  return -1;
}

// One packing at `scale` texels per UV unit; false if it overflows the square.
bool pack_at(const std::vector<PackChart>& charts, const std::vector<Vec2>& sizes,
             const std::vector<int>& order, double scale, int texture_size, double padding,
             int cells, std::vector<Placement>& placements) {
  const double cell = static_cast<double>(texture_size) / cells;
  const double half = 0.5 * padding;
  Occupancy occ(cells);
  placements.assign(charts.size(), {});
  for (int ci : order) {
    int best_top = cells + 1;
    Placement best;
    CellShape best_shape;
    for (int r = 0; r < 4; ++r) {
      CellShape s = cell_shape(
          profile(*charts[ci].uv, *charts[ci].triangles, r, sizes[ci], scale, half, cell), cell);
      const int w = static_cast<int>(s.lo.size());
      for (int x = 0; x + w <= cells; ++x) {
        int y = lowest_fit(occ, s, x, cells, best_top);
        if (y < 0 || y + s.height >= best_top) continue;
        best_top = y + s.height;
        best = {r, x, y};
        best_shape = s;
      }
    }
    if (best_top > cells) return false;
    for (size_t c = 0; c < best_shape.lo.size(); ++c)
      if (best_shape.lo[c] <= best_shape.hi[c])
        occ.fill(best.column + static_cast<int>(c), best.row + best_shape.lo[c], best.row + best_shape.hi[c]);
    placements[ci] = best;
  }
  return true;
}

}  // namespace

PackResult pack_charts(std::vector<PackChart>& charts, int texture_size, double padding_px) {
  PackResult result;
  const int n = static_cast<int>(charts.size());
  std::vector<Vec2> sizes(n);
  double area = 0;
  for (int i = 0; i < n; ++i) {
    sizes[i] = align_to_min_rectangle(*charts[i].uv);
    for (const auto& t : *charts[i].triangles) {
      const auto& uv = *charts[i].uv;
      area += 0.5 * std::fabs(cross(uv[t[1]] - uv[t[0]], uv[t[2]] - uv[t[0]]));
    }
  }
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    return sizes[a].x * sizes[a].y > sizes[b].x * sizes[b].y;
  });
  // Cells of about four texels at 2048: finer buys little packing density for
  // much more placement work.
  const int columns = std::max(16, std::min(texture_size, 2048) / 4);

  std::vector<Placement> placements, best_placements;
  double hi = texture_size / std::sqrt(std::max(area, 1e-300));  // 100% utilisation
  double lo = 0;
  for (double s = hi * 0.9; s > hi * 1e-12; s *= 0.7) {
    ++result.attempts;
    if (pack_at(charts, sizes, order, s, texture_size, padding_px, columns, placements)) {
      lo = s;
      best_placements = placements;
      break;
    }
    hi = s;
  }
  if (lo == 0)
    throw Error(ErrorCode::limit_exceeded,
                "atlas: " + std::to_string(n) + " charts do not fit a " +
                    std::to_string(texture_size) + " texture with " +
                    std::to_string(padding_px) + " px padding");
  for (int it = 0; it < 10 && hi / lo > 1.005; ++it) {
    double s = std::sqrt(lo * hi);
    ++result.attempts;
    if (pack_at(charts, sizes, order, s, texture_size, padding_px, columns, placements)) {
      lo = s;
      best_placements = placements;
    } else {
      hi = s;
    }
  }

  const double column_width = static_cast<double>(texture_size) / columns;
  const double half = 0.5 * padding_px;
  double uv_area = 0;
  for (int i = 0; i < n; ++i) {
    const Placement& p = best_placements[i];
    for (Vec2& q : *charts[i].uv) {
      Vec2 t = turn(q, p.rotation, sizes[i]);
      q = {(p.column * column_width + t.x * lo + half) / texture_size,
           (p.row * column_width + t.y * lo + half) / texture_size};
    }
    for (const auto& t : *charts[i].triangles) {
      const auto& uv = *charts[i].uv;
      uv_area += 0.5 * std::fabs(cross(uv[t[1]] - uv[t[0]], uv[t[2]] - uv[t[0]]));
    }
  }
  result.uv_per_length = lo / texture_size;
  result.utilization = uv_area;
  return result;
}

}  // namespace soupuv::atlas
