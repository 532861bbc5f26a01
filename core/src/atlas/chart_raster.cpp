#include "atlas/chart_raster.h"

#include <algorithm>
#include <cmath>

namespace soupuv::atlas {
namespace {

struct RowSpan {
  int row, a, b;
  bool operator<(const RowSpan& o) const { return row != o.row ? row < o.row : a < o.a; }
};

// Sorts the spans and merges overlapping or touching ones into a RowMask.
RowMask assemble(std::vector<RowSpan>& raw, int height) {
  // Rows are few per span: bucket by row, then sort the short runs.
  std::vector<int> start(height + 1, 0);
  for (const RowSpan& r : raw) ++start[r.row + 1];
  for (int j = 0; j < height; ++j) start[j + 1] += start[j];
  std::vector<RowSpan> sorted(raw.size());
  std::vector<int> at(start.begin(), start.end() - 1);
  for (const RowSpan& r : raw) sorted[at[r.row]++] = r;
  for (int j = 0; j < height; ++j) std::sort(sorted.begin() + start[j], sorted.begin() + start[j + 1]);
  raw.swap(sorted);
  RowMask m;
  m.height = height;
  m.first.assign(height + 1, 0);
  for (size_t i = 0; i < raw.size();) {
    RowSpan cur = raw[i++];
    while (i < raw.size() && raw[i].row == cur.row && raw[i].a <= cur.b + 1) cur.b = std::max(cur.b, raw[i++].b);
    m.spans.push_back({cur.a, cur.b});
    ++m.first[cur.row + 1];
    m.width = std::max(m.width, cur.b + 1);
    m.texels += cur.b - cur.a + 1;
  }
  for (int r = 0; r < height; ++r) m.first[r + 1] += m.first[r];
  return m;
}

}  // namespace

RowMask rasterize_outline(const std::vector<Vec2>& outline) {
  std::vector<std::array<int, 2>> segments(outline.size());
  for (size_t i = 0; i < outline.size(); ++i)
    segments[i] = {static_cast<int>(i), static_cast<int>((i + 1) % outline.size())};
  return rasterize_segments(outline, segments);
}

RowMask rasterize_segments(const std::vector<Vec2>& points,
                           const std::vector<std::array<int, 2>>& segments) {
  std::vector<RowSpan> raw;
  const size_t n = segments.size();
  double top = 0;
  for (const auto& s : segments) top = std::max({top, points[s[0]].y, points[s[1]].y});
  const int height = static_cast<int>(std::floor(top)) + 1;
  // Boundary texels: the x-range of each segment within each row strip. A
  // point belongs to texel (floor x, floor y); that is all the padding
  // argument needs (see the header).
  for (size_t i = 0; i < n; ++i) {
    Vec2 p = points[segments[i][0]], q = points[segments[i][1]];
    if (p.y > q.y) std::swap(p, q);
    const int j0 = static_cast<int>(std::floor(p.y)), j1 = static_cast<int>(std::floor(q.y));
    for (int j = j0; j <= j1; ++j) {
      // The part of the segment with j <= y <= j + 1 (the end on y = j + 1
      // belongs to the next row; counting it here too only over-covers).
      double xa = p.x, xb = q.x;
      if (q.y > p.y) {
        const double ya = std::max(p.y, static_cast<double>(j)), yb = std::min(q.y, j + 1.0);
        xa = p.x + (q.x - p.x) * (ya - p.y) / (q.y - p.y);
        xb = p.x + (q.x - p.x) * (yb - p.y) / (q.y - p.y);
        // Rounding must not carry a point past its segment's ends (x < 0
        // would leave the mask's frame).
        xa = std::clamp(xa, std::min(p.x, q.x), std::max(p.x, q.x));
        xb = std::clamp(xb, std::min(p.x, q.x), std::max(p.x, q.x));
      }
      // A segment ending exactly on the strip's lower line touches row j - 1's
      // texels too; the segment before or after it covers that row as well
      // unless it is horizontal there, which this loop's own row covers.
      raw.push_back({j, static_cast<int>(std::floor(std::min(xa, xb))),
                     static_cast<int>(std::floor(std::max(xa, xb)))});
    }
  }
  // Interior texels: their centres are inside (even-odd rule on the row's
  // centre line y = j + 1/2, half-open in y so a vertex on it counts once).
  std::vector<std::vector<double>> crossings(height);
  for (size_t i = 0; i < n; ++i) {
    Vec2 p = points[segments[i][0]], q = points[segments[i][1]];
    if (p.y > q.y) std::swap(p, q);
    // Rows whose centre c satisfies p.y <= c < q.y.
    const int j0 = static_cast<int>(std::ceil(p.y - 0.5)), j1 = static_cast<int>(std::ceil(q.y - 0.5)) - 1;
    for (int j = std::max(0, j0); j <= std::min(height - 1, j1); ++j) {
      const double c = j + 0.5;
      crossings[j].push_back(p.x + (q.x - p.x) * (c - p.y) / (q.y - p.y));
    }
  }
  for (int j = 0; j < height; ++j) {
    auto& xs = crossings[j];
    std::sort(xs.begin(), xs.end());
    for (size_t k = 0; k + 1 < xs.size(); k += 2) {
      // Texels i with xs[k] <= i + 1/2 <= xs[k+1].
      const int a = static_cast<int>(std::ceil(xs[k] - 0.5)), b = static_cast<int>(std::floor(xs[k + 1] - 0.5));
      if (a <= b) raw.push_back({j, a, b});
    }
  }
  return assemble(raw, height);
}

RowMask dilate(const RowMask& mask, int r) {
  const int height = mask.height + 2 * r;
  std::vector<RowSpan> raw;
  raw.reserve(mask.spans.size() * (2 * r + 1));
  for (int j = 0; j < mask.height; ++j)
    for (int s = mask.first[j]; s < mask.first[j + 1]; ++s)
      for (int d = 0; d <= 2 * r; ++d) raw.push_back({j + d, mask.spans[s].a, mask.spans[s].b + 2 * r});
  return assemble(raw, height);
}

}  // namespace soupuv::atlas
