#include "uvsolve/sliver_stack.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <unordered_map>

#include <Eigen/Dense>

#include "soupuv/union_find.h"

namespace soupuv::uvsolve::detail {
namespace {

// A sliver: altitude below this many noise amplitudes (a row of the stack
// is thinner than twice the amplitude; the noise adds up to about two more
// across and two more off the plane, and a sliver left out leaves a hole in
// its column) ...
constexpr double kThinNoise = 6;
// ... and below this share of its longest edge, which is at least this
// many amplitudes long (its ends resolved, well apart from the next
// column's).
constexpr double kMaxAspect = 0.25;
constexpr double kLongNoise = 8;
// Welded slivers whose long edges meet at a cosine of at least this are in
// one stack (a sliver's long edge is at least 8 amplitudes long, so the
// noise turns it by at most ~14 degrees at the extreme; a stack's columns
// share their direction).
constexpr double kParallelCos = 0.95;
// Parallel slivers whose centroids lie within this many amplitudes are in
// one stack too (the next row of a column is under one amplitude away).
constexpr double kNearNoise = 3;
// Column ends closer than this many amplitudes along the stack are one
// column boundary.
constexpr double kEndGapNoise = 3;
// A stack is flat across when its corners' RMS distance from its plane is
// at most this many amplitudes (uniform noise alone: 1 / sqrt 3).
constexpr double kFlatNoise = 1;
// A side of a group that is not flat: sliver centroids within this many
// amplitudes of one line across the slivers (a centroid is off its side by
// a third of the noise of three corners); at most kMaxSides sides.
constexpr double kSideNoise = 1;
constexpr size_t kMaxSides = 8;
constexpr size_t kLineSearchSample = 4096;

// The soup's slivers: per triangle whether it is one, its long edge's
// direction and the corner opposite its shortest edge (its tip).
struct Slivers {
  std::vector<uint8_t> thin;
  std::vector<Vec3> along;
  std::vector<int> tip;
};

// A sliver of a stack, in the stack's frame.
struct Sliver {
  uint32_t t;
  int tip;           // corner opposite the shortest edge
  bool short_left;   // the short edge at the lower end along the stack
  double lo, hi;     // the two ends along the stack (short edge's middle, tip)
  double height;     // centroid across the stack
};

// The frame of a group: u along the slivers, v across them in the plane of
// their corners; off_plane: the corners' RMS distance from that plane.
struct StackFrame {
  Vec3 u, v;
  double off_plane = 0;
};

// A stack ready for its grid: its slivers, the column boundaries along u,
// per column (index of its lower boundary) the slivers whose short edge is
// on its left and on its right, the columns kept, the rows and their
// height across, from v_lo.
struct Stack {
  std::vector<Sliver> slivers;
  std::vector<double> boundary;
  std::map<int, std::vector<int>> left, right;
  std::vector<int> columns;
  size_t rows = 0;
  double v_lo = 0, row_height = 0;
};

Vec3 any_perpendicular(Vec3 u) {
  const Vec3 a = std::fabs(u.x) < 0.6 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
  return normalized(cross(u, a));
}

// The direction along a group of slivers: of the principal axes of its
// corners, the one nearest the slivers' mean long edge. The long edges
// themselves lean: a quad's longest edge is its diagonal, which leans by
// row height / column width (1.7 degrees on the table's top), enough to
// shift a 2-unit band's far end across its whole height.
Vec3 stack_axis(const Soup& soup, const std::vector<uint32_t>& tris, const std::vector<Vec3>& along) {
  Vec3 mean_along{0, 0, 0};
  for (uint32_t t : tris) mean_along += dot(along[t], along[tris[0]]) >= 0 ? along[t] : -along[t];
  Vec3 m{0, 0, 0};
  for (uint32_t t : tris)
    for (int k = 0; k < 3; ++k) m += soup.corner(t, k);
  m = m / (3.0 * double(tris.size()));
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (uint32_t t : tris)
    for (int k = 0; k < 3; ++k) {
      const Vec3 d = soup.corner(t, k) - m;
      const Eigen::Vector3d e(d.x, d.y, d.z);
      cov += e * e.transpose();
    }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  Vec3 best = normalized(mean_along);
  double best_cos = -1;
  for (int i = 0; i < 3; ++i) {
    const Vec3 axis{eig.eigenvectors()(0, i), eig.eigenvectors()(1, i), eig.eigenvectors()(2, i)};
    const double c = std::fabs(dot(axis, mean_along));
    if (c > best_cos) best_cos = c, best = dot(axis, mean_along) >= 0 ? axis : -axis;
  }
  return normalized(best);
}

// The flat sides of a group of parallel slivers that is not flat (a thin
// bar's four sides): in the cross-section across the slivers, the line
// through the most sliver centroids within kSideNoise amplitudes (angles
// by one degree) is a side; its slivers are taken out and the next line
// sought while one holds at least four. Largest side first.
std::vector<std::vector<uint32_t>> flat_sides(const Soup& soup, const std::vector<uint32_t>& tris,
                                              const std::vector<Vec3>& along, double a) {
  const Vec3 u = stack_axis(soup, tris, along);
  const Vec3 e1 = any_perpendicular(u), e2 = cross(u, e1);
  std::vector<Vec2> c(tris.size());
  for (size_t i = 0; i < tris.size(); ++i) {
    const Vec3 m = (soup.corner(tris[i], 0) + soup.corner(tris[i], 1) + soup.corner(tris[i], 2)) / 3;
    c[i] = {dot(m, e1), dot(m, e2)};
  }
  std::vector<uint32_t> left(tris.size());
  for (size_t i = 0; i < left.size(); ++i) left[i] = uint32_t(i);
  std::vector<std::vector<uint32_t>> sides;
  std::vector<double> proj;
  const double half = kSideNoise * a;
  while (sides.size() < kMaxSides && left.size() >= 4) {
    size_t best = 0;
    Vec2 normal{1, 0};
    double offset = 0;
    // The search looks at no more than kLineSearchSample centroids (every
    // stride-th): 180 sorts of a group of a million would take seconds.
    const size_t stride = (left.size() + kLineSearchSample - 1) / kLineSearchSample;
    for (int degree = 0; degree < 180; ++degree) {
      const Vec2 nrm{std::cos(degree * M_PI / 180), std::sin(degree * M_PI / 180)};
      proj.clear();
      for (size_t q = 0; q < left.size(); q += stride) proj.push_back(dot(c[left[q]], nrm));
      std::sort(proj.begin(), proj.end());
      for (size_t lo = 0, hi = 0; hi < proj.size(); ++hi) {
        while (proj[hi] - proj[lo] > 2 * half) ++lo;
        if (hi - lo + 1 > best) best = hi - lo + 1, normal = nrm, offset = 0.5 * (proj[lo] + proj[hi]);
      }
    }
    if (best < 4) break;
    // The line refitted to the centroids it holds (least squares, twice):
    // the search's one-degree steps tilt it by up to half a degree, which
    // over a long side leaves its ends' centroids out.
    for (int refit = 0; refit < 2; ++refit) {
      Vec2 m{0, 0};
      size_t k = 0;
      for (uint32_t i : left)
        if (std::fabs(dot(c[i], normal) - offset) <= half) m = m + c[i], ++k;
      if (k < 2) break;
      m = (1.0 / double(k)) * m;
      double sxx = 0, sxy = 0, syy = 0;
      for (uint32_t i : left)
        if (std::fabs(dot(c[i], normal) - offset) <= half) {
          const Vec2 d = c[i] - m;
          sxx += d.x * d.x, sxy += d.x * d.y, syy += d.y * d.y;
        }
      const double angle = 0.5 * std::atan2(2 * sxy, sxx - syy);  // the line's direction
      normal = {-std::sin(angle), std::cos(angle)};
      offset = dot(m, normal);
    }
    std::vector<uint32_t> side_tris, rest;
    for (uint32_t i : left) {
      if (std::fabs(dot(c[i], normal) - offset) <= half)
        side_tris.push_back(tris[i]);
      else
        rest.push_back(i);
    }
    if (side_tris.size() < 4) break;
    sides.push_back(std::move(side_tris));
    left = std::move(rest);
  }
  return sides;
}

double estimate_noise(const Soup& soup, const std::vector<geometry::AdjacentPair>& pairs) {
  double sum = 0;
  size_t count = 0;
  for (const auto& p : pairs)
    for (int k = 0; k < 2; ++k) {
      sum += norm2(soup.corner(p.a, p.a_corner[k]) - soup.corner(p.b, p.b_corner[k]));
      ++count;
    }
  return count ? std::sqrt(sum / double(count) / 2) : 0;
}

Slivers find_slivers(const Soup& soup, double a) {
  const size_t n = soup.triangles.size();
  Slivers s{std::vector<uint8_t>(n, 0), std::vector<Vec3>(n), std::vector<int>(n, 0)};
  for (size_t t = 0; t < n; ++t) {
    double len[3];  // len[k]: the edge opposite corner k
    for (int k = 0; k < 3; ++k) len[k] = norm(soup.corner(t, (k + 2) % 3) - soup.corner(t, (k + 1) % 3));
    const int longest = int(std::max_element(len, len + 3) - len);
    const int shortest = int(std::min_element(len, len + 3) - len);
    const double area2 = norm(cross(soup.corner(t, 1) - soup.corner(t, 0), soup.corner(t, 2) - soup.corner(t, 0)));
    const double altitude = len[longest] > 0 ? area2 / len[longest] : 0;
    if (shortest == longest || len[longest] < kLongNoise * a || altitude >= kThinNoise * a ||
        altitude >= kMaxAspect * len[longest])
      continue;
    s.thin[t] = 1;
    s.tip[t] = shortest;
    s.along[t] = normalized(soup.corner(t, (longest + 2) % 3) - soup.corner(t, (longest + 1) % 3));
  }
  return s;
}

// Parallel slivers welded to each other, or whose centroids lie within
// kNearNoise amplitudes (the row above or below in a column: the weld
// leaves some slivers of a scrambled stack with no partner at all), in
// the order of their smallest triangle.
std::vector<std::vector<uint32_t>> parallel_groups(const Soup& soup, const Slivers& s,
                                                   const std::vector<geometry::AdjacentPair>& pairs, double a) {
  const size_t n = s.thin.size();
  UnionFind groups(n);
  auto parallel = [&](uint32_t x, uint32_t y) { return std::fabs(dot(s.along[x], s.along[y])) >= kParallelCos; };
  for (const auto& p : pairs)
    if (s.thin[p.a] && s.thin[p.b] && parallel(p.a, p.b)) groups.unite(p.a, p.b);
  const double reach = kNearNoise * a;
  std::unordered_map<uint64_t, std::vector<uint32_t>> cells;
  std::vector<Vec3> centroid(n);
  auto cell_key = [&](int64_t x, int64_t y, int64_t z) {
    return (uint64_t(x) * 0x9E3779B97F4A7C15ull) ^ (uint64_t(y) * 0xC2B2AE3D27D4EB4Full) ^
           (uint64_t(z) * 0x165667B19E3779F9ull);
  };
  auto cell_of = [&](Vec3 c, int64_t& x, int64_t& y, int64_t& z) {
    x = int64_t(std::floor(c.x / reach)), y = int64_t(std::floor(c.y / reach)), z = int64_t(std::floor(c.z / reach));
  };
  for (uint32_t t = 0; t < n; ++t) {
    if (!s.thin[t]) continue;
    centroid[t] = (soup.corner(t, 0) + soup.corner(t, 1) + soup.corner(t, 2)) / 3;
    int64_t x, y, z;
    cell_of(centroid[t], x, y, z);
    cells[cell_key(x, y, z)].push_back(t);
  }
  for (uint32_t t = 0; t < n; ++t) {
    if (!s.thin[t]) continue;
    int64_t x, y, z;
    cell_of(centroid[t], x, y, z);
    for (int64_t dx = -1; dx <= 1; ++dx)
      for (int64_t dy = -1; dy <= 1; ++dy)
        for (int64_t dz = -1; dz <= 1; ++dz) {
          auto it = cells.find(cell_key(x + dx, y + dy, z + dz));
          if (it == cells.end()) continue;
          for (uint32_t o : it->second)
            if (o > t && norm2(centroid[o] - centroid[t]) <= reach * reach && parallel(o, t)) groups.unite(o, t);
        }
  }
  std::map<uint32_t, std::vector<uint32_t>> members;
  for (size_t t = 0; t < n; ++t)
    if (s.thin[t]) members[groups.find(uint32_t(t))].push_back(uint32_t(t));
  std::vector<std::vector<uint32_t>> out;
  for (auto& [root, tris] : members) out.push_back(std::move(tris));
  return out;
}

StackFrame stack_frame(const Soup& soup, const std::vector<uint32_t>& tris, const std::vector<Vec3>& along) {
  StackFrame f;
  f.u = stack_axis(soup, tris, along);
  const Vec3 e1 = any_perpendicular(f.u), e2 = cross(f.u, e1);
  double m1 = 0, m2 = 0;
  for (uint32_t t : tris)
    for (int k = 0; k < 3; ++k) m1 += dot(soup.corner(t, k), e1), m2 += dot(soup.corner(t, k), e2);
  const double count = 3.0 * double(tris.size());
  m1 /= count, m2 /= count;
  double c11 = 0, c12 = 0, c22 = 0;
  for (uint32_t t : tris)
    for (int k = 0; k < 3; ++k) {
      const double x = dot(soup.corner(t, k), e1) - m1, y = dot(soup.corner(t, k), e2) - m2;
      c11 += x * x, c12 += x * y, c22 += y * y;
    }
  // The 2x2 covariance across u: its smaller eigenvalue is the spread off
  // the plane, the eigenvector of the larger one is v.
  const double tr = c11 + c22, det = c11 * c22 - c12 * c12;
  const double small = 0.5 * (tr - std::sqrt(std::max(0.0, tr * tr - 4 * det)));
  const double big = tr - small;
  f.off_plane = std::sqrt(small / count);
  f.v = std::fabs(c12) > 1e-300 ? normalized((big - c22) * e1 + c12 * e2) : (c11 >= c22 ? e1 : e2);
  return f;
}

// The group's slivers sorted into columns and rows (Stack); false if the
// group is no stack whose rows the noise scrambles: fewer than two rows or
// two columns, or rows at least twice the noise amplitude tall.
bool build_stack(const Soup& soup, const std::vector<uint32_t>& tris, const std::vector<int>& tip,
                 const StackFrame& f, double a, Stack& st) {
  // Each sliver's ends along u and height along v.
  auto& s = st.slivers;
  s.reserve(tris.size());
  for (uint32_t t : tris) {
    const int k = tip[t];
    const Vec3 mid = 0.5 * (soup.corner(t, (k + 1) % 3) + soup.corner(t, (k + 2) % 3));
    const double tip_u = dot(soup.corner(t, k), f.u), mid_u = dot(mid, f.u);
    Sliver x;
    x.t = t;
    x.tip = k;
    x.short_left = mid_u < tip_u;
    x.lo = std::min(tip_u, mid_u);
    x.hi = std::max(tip_u, mid_u);
    x.height = dot(soup.corner(t, 0) + soup.corner(t, 1) + soup.corner(t, 2), f.v) / 3;
    s.push_back(x);
  }
  // Column boundaries: the ends clustered along u.
  std::vector<double> ends;
  for (const Sliver& x : s) ends.push_back(x.lo), ends.push_back(x.hi);
  std::sort(ends.begin(), ends.end());
  std::vector<double> cut;  // upper limit of each cluster
  double sum = ends[0];
  int in_cluster = 1;
  for (size_t i = 1; i <= ends.size(); ++i) {
    if (i == ends.size() || ends[i] - ends[i - 1] > kEndGapNoise * a) {
      st.boundary.push_back(sum / in_cluster);
      cut.push_back(i < ends.size() ? 0.5 * (ends[i - 1] + ends[i]) : INFINITY);
      if (i == ends.size()) break;
      sum = 0, in_cluster = 0;
    }
    sum += ends[i], ++in_cluster;
  }
  auto cluster_of = [&](double e) { return int(std::lower_bound(cut.begin(), cut.end(), e) - cut.begin()); };
  // Columns: slivers spanning two consecutive boundaries.
  for (int i = 0; i < int(s.size()); ++i) {
    const int b0 = cluster_of(s[i].lo), b1 = cluster_of(s[i].hi);
    if (b1 == b0 + 1) (s[i].short_left ? st.left : st.right)[b0].push_back(i);
  }
  // Rows: the most slivers a column has on one side. A column with fewer
  // than half as many on a side is left to its islands; one with a few
  // missing (joined to the stack by no weld pair, not thin enough under
  // the noise, or a neighbouring side's sliver taken in at a corner) has
  // its slivers placed in order in the rows nearest their heights.
  for (const auto& [c, l] : st.left) {
    auto r = st.right.find(c);
    if (r != st.right.end()) st.rows = std::max({st.rows, l.size(), r->second.size()});
  }
  for (const auto& [c, l] : st.left) {
    auto r = st.right.find(c);
    if (r == st.right.end()) continue;
    const size_t fewer = std::min(l.size(), r->second.size()), more = std::max(l.size(), r->second.size());
    if (more <= st.rows && 2 * fewer >= st.rows) st.columns.push_back(c);
  }
  double v_lo = INFINITY, v_hi = -INFINITY;
  for (int c : st.columns)
    for (const auto* side : {&st.left[c], &st.right[c]})
      for (int i : *side)
        for (int k = 0; k < 3; ++k) {
          const double h = dot(soup.corner(s[i].t, k), f.v);
          v_lo = std::min(v_lo, h), v_hi = std::max(v_hi, h);
        }
  st.v_lo = v_lo;
  st.row_height = (v_hi - v_lo) / double(st.rows);
  return st.rows >= 2 && st.columns.size() >= 2 && st.row_height > 0 && st.row_height < 2 * a;
}

// Whether the grid would keep more of the weld's pairs than the islands
// the stack is in now: the grid keeps the pairs inside the stack and cuts
// those to the rest of the part (its island is packed apart). Where the
// weld held (the enclosure's lid: rows 1.9 noise amplitudes tall, 91-98 %
// of the pairs inside kept) the islands keep more.
bool grid_keeps_more(const std::vector<geometry::AdjacentPair>& pairs, Stack& st, const UvLayout& layout) {
  std::vector<uint8_t> in(layout.island.size(), 0);
  for (int c : st.columns)
    for (const auto* side : {&st.left[c], &st.right[c]})
      for (int i : *side) in[st.slivers[i].t] = 1;
  size_t cut_inside = 0, kept_across = 0;
  for (const auto& p : pairs) {
    if (!in[p.a] && !in[p.b]) continue;
    const bool kept = layout.corner_vertex[p.a][p.a_corner[0]] == layout.corner_vertex[p.b][p.b_corner[0]] &&
                      layout.corner_vertex[p.a][p.a_corner[1]] == layout.corner_vertex[p.b][p.b_corner[1]];
    if (in[p.a] && in[p.b])
      cut_inside += !kept;
    else
      kept_across += kept;
  }
  return cut_inside > kept_across;
}

// The rows of one column side's slivers (idx, sorted here by height): in
// order, each in the row whose sliver centroid height (a third or two
// thirds up the row, as its tip sits low or high) is nearest, by dynamic
// programming over (sliver, row): O(slivers x rows).
std::vector<int> rows_in_order(const Stack& st, std::vector<int>& idx, bool tip_low) {
  const auto& s = st.slivers;
  std::stable_sort(idx.begin(), idx.end(), [&](int x, int y) { return s[x].height < s[y].height; });
  const int m = int(idx.size()), R = int(st.rows);
  const double f = tip_low ? 1.0 / 3 : 2.0 / 3;
  // cost[i * R + r]: least total distance with sliver i in row r.
  std::vector<double> cost(size_t(m) * R, INFINITY);
  std::vector<int> from(size_t(m) * R, -1);
  for (int i = 0; i < m; ++i) {
    double best = INFINITY;
    int best_r = -1;
    for (int r = i; r <= R - m + i; ++r) {
      if (i > 0 && cost[size_t(i - 1) * R + r - 1] < best) best = cost[size_t(i - 1) * R + r - 1], best_r = r - 1;
      const double d = std::fabs(s[idx[i]].height - (st.v_lo + (r + f) * st.row_height));
      cost[size_t(i) * R + r] = (i == 0 ? 0 : best) + d;
      from[size_t(i) * R + r] = best_r;
    }
  }
  std::vector<int> row(m);
  int r = int(std::min_element(cost.begin() + size_t(m - 1) * R, cost.begin() + size_t(m) * R) -
              (cost.begin() + size_t(m - 1) * R));
  for (int i = m - 1; i >= 0; --i) row[i] = r, r = from[size_t(i) * R + r];
  return row;
}

// The stack as one new island of the layout, a grid: vertex (boundary b,
// row line r) at (boundary[b], r row_height) from the first column,
// mirrored across when the stack's orientation is negative. Each sliver's
// short edge spans its row on its side, its tip on the other side at the
// bottom or the top (the quad's diagonal, by the stack's majority), the
// two halves tiling the quad; its corners swapped where that makes it
// counter-clockwise. -> triangles laid.
size_t lay_grid(const Soup& soup, const StackFrame& f, double uv_per_length, Stack& st, UvLayout& layout) {
  const auto& s = st.slivers;
  // The diagonal: does a left sliver's tip sit at the bottom of its row?
  // And the orientation: the sign most slivers have in (u, v), weighted by
  // their area there (the soup's corner order is the original's).
  long tip_low = 0;
  double orientation = 0;
  for (int c : st.columns) {
    for (int i : st.left[c]) {
      const uint32_t t = s[i].t;
      const int k = s[i].tip;
      const double mid = 0.5 * (dot(soup.corner(t, (k + 1) % 3), f.v) + dot(soup.corner(t, (k + 2) % 3), f.v));
      tip_low += dot(soup.corner(t, k), f.v) < mid ? 1 : -1;
    }
    for (const auto* side : {&st.left[c], &st.right[c]})
      for (int i : *side) {
        const uint32_t t = s[i].t;
        Vec2 p[3];
        for (int k = 0; k < 3; ++k) p[k] = {dot(soup.corner(t, k), f.u), dot(soup.corner(t, k), f.v)};
        orientation += cross(p[1] - p[0], p[2] - p[0]);
      }
  }
  const double sign = orientation >= 0 ? 1 : -1;
  const bool left_tip_low = tip_low >= 0;

  const uint32_t island = layout.island_count++;
  std::map<std::pair<int, int>, uint32_t> grid;
  auto vertex = [&](int b, int r) {
    auto [it, fresh] = grid.try_emplace({b, r}, uint32_t(layout.uv.size()));
    if (fresh)
      layout.uv.push_back(uv_per_length *
                          Vec2{st.boundary[b] - st.boundary[st.columns.front()], sign * r * st.row_height});
    return it->second;
  };
  size_t laid = 0;
  for (int c : st.columns)
    for (bool left : {true, false}) {
      auto& idx = (left ? st.left : st.right)[c];
      const int side = left ? c : c + 1, other = left ? c + 1 : c;
      const bool tip_low_here = left ? left_tip_low : !left_tip_low;
      const std::vector<int> row_of = rows_in_order(st, idx, tip_low_here);
      for (size_t j = 0; j < idx.size(); ++j) {
        const Sliver& x = s[idx[j]];
        const int row = row_of[j];
        const uint32_t bottom = vertex(side, row), top = vertex(side, row + 1);
        const uint32_t apex = vertex(other, tip_low_here ? row : row + 1);
        auto& cv = layout.corner_vertex[x.t];
        const int k1 = (x.tip + 1) % 3, k2 = (x.tip + 2) % 3;
        cv[x.tip] = apex;
        cv[k1] = bottom, cv[k2] = top;
        if (signed_area2(layout, x.t) < 0) std::swap(cv[k1], cv[k2]);
        layout.island[x.t] = island;
        if (!layout.unfolded.empty()) layout.unfolded[x.t] = 0;
        ++laid;
      }
    }
  return laid;
}

}  // namespace

SliverStackFigures lay_sliver_stacks(const Soup& soup, const std::vector<geometry::AdjacentPair>& pairs,
                                     double uv_per_length, UvLayout& layout) {
  SliverStackFigures fig;
  const double a = estimate_noise(soup, pairs);
  fig.noise = a;
  if (!(a > 0)) return fig;
  const Slivers slivers = find_slivers(soup, a);

  enum class Outcome { laid, kept, skipped, not_flat };
  auto lay = [&](const std::vector<uint32_t>& tris) {
    if (tris.size() < 4) return Outcome::skipped;
    const StackFrame f = stack_frame(soup, tris, slivers.along);
    if (f.off_plane > kFlatNoise * a) return Outcome::not_flat;
    Stack st;
    if (!build_stack(soup, tris, slivers.tip, f, a, st)) return Outcome::skipped;
    if (!grid_keeps_more(pairs, st, layout)) {
      ++fig.kept_by_islands;
      return Outcome::kept;
    }
    fig.triangles += lay_grid(soup, f, uv_per_length, st, layout);
    ++fig.stacks;
    fig.columns += st.columns.size();
    return Outcome::laid;
  };
  for (const auto& tris : parallel_groups(soup, slivers, pairs, a)) {
    if (tris.size() < 4) continue;
    Outcome o = lay(tris);
    if (o == Outcome::not_flat) {
      // Several flat sides along one direction (a thin bar's four sides):
      // each side peeled off and laid on its own.
      for (const auto& side : flat_sides(soup, tris, slivers.along, a)) {
        const Outcome side_outcome = lay(side);
        if (side_outcome == Outcome::laid || (side_outcome == Outcome::kept && o != Outcome::laid)) o = side_outcome;
      }
    }
    if (o == Outcome::skipped || o == Outcome::not_flat) ++fig.skipped_stacks;
  }
  if (fig.stacks) compact_island_ids(layout);
  return fig;
}

}  // namespace soupuv::uvsolve::detail
