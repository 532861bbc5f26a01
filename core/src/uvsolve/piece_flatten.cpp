#include "uvsolve/piece_flatten.h"

#include <algorithm>
#include <cmath>

#include "atlas/parameterize.h"
#include "soupuv/geometry/triangle_stretch.h"
#include "transfer/slim.h"
#include "uvsolve/overlap_split.h"

namespace soupuv::uvsolve::detail {

namespace {
// The most samples a piece's lap test takes over its area (see flatten).
constexpr double kMaxLapSamples = double(1 << 17);
// After kProbeIterations of SLIM, a piece whose L2 stretch is still above
// kHopelessStretch times the budget is refused there: over the corpus's
// mid-size soups no piece that far above it after three iterations came
// within the budget by the tenth (the kept ones were at most 0.97 of it),
// and the refused unions are the largest (docs/tuning.md, session 33).
constexpr int kProbeIterations = 3;
constexpr double kHopelessStretch = 1.3;
// From the probe on, a piece above the budget is also refused as soon as
// its stretch, falling for every iteration left at the best rate of its
// last two, would still end above it: the refused unions of the CAD soups
// stalled there (table-exact's largest, 10,454 triangles: 1.321 at the
// 4th iteration, 1.308 at the 10th, budget 1.25), and SLIM's last
// iterations on them were most of the union merge's time. The rate is that
// of the L2 stretch the refusal is judged by, not of SLIM's energy. It is
// a forecast: over the corpus and the shared samples the maps are the same
// bit for bit but on the two scans, where a few noisy pieces of thousands
// fell late (their figures equal; docs/tuning.md, session 36).

// Above this many triangles a flattening costs more per triangle, about as
// the square root of its size (flatten_cost).
constexpr double kFlattenCostKnee = 3000;

// The piece's UVs as corners per triangle.
std::vector<std::array<Vec2, 3>> corners_of(const PieceMesh& m, const std::vector<Vec2>& uv) {
  std::vector<std::array<Vec2, 3>> corners(m.triangles.size());
  for (size_t j = 0; j < m.triangles.size(); ++j)
    for (int k = 0; k < 3; ++k) corners[j][k] = uv[m.triangles[j][k]];
  return corners;
}

uint32_t find(std::vector<uint32_t>& parent, uint32_t x) {
  while (parent[x] != x) x = parent[x] = parent[parent[x]];
  return x;
}
}  // namespace

double rest_stretch_l2(const std::vector<transfer::detail::RestTriangle>& rest,
                       const std::vector<std::array<Vec2, 3>>& corners) {
  double sum_l2 = 0, a3 = 0, a2 = 0;
  for (size_t k = 0; k < rest.size(); ++k) {
    const transfer::detail::RestTriangle& r = rest[k];
    if (!r.valid) continue;
    const geometry::TriangleStretch s = geometry::triangle_stretch(
        {Vec3{r.x[0].x, r.x[0].y, 0}, Vec3{r.x[1].x, r.x[1].y, 0}, Vec3{r.x[2].x, r.x[2].y, 0}}, corners[k]);
    sum_l2 += s.l2_squared * s.area3d;
    a3 += s.area3d;
    a2 += std::max(0.0, s.area_uv);
  }
  if (a3 <= 0) return 1;
  return std::sqrt(sum_l2 / a3) * std::sqrt(a2 / a3);
}

PieceMesh piece_mesh(const Soup& soup, double uv_per_length, const std::vector<uint32_t>& tris, const UvLayout& L,
                     const std::vector<uint32_t>* vertex_of) {
  PieceMesh m;
  const size_t nf = tris.size();
  struct HalfEdge {
    uint64_t key;  // undirected: smaller layout vertex first
    uint32_t face;
    uint8_t k;     // from corner k to k + 1
    bool forward;  // smaller vertex is corner k
  };
  std::vector<HalfEdge> half;
  half.reserve(3 * nf);
  for (uint32_t j = 0; j < nf; ++j)
    for (uint8_t k = 0; k < 3; ++k) {
      uint32_t a = L.corner_vertex[tris[j]][k], b = L.corner_vertex[tris[j]][(k + 1) % 3];
      if (vertex_of) a = (*vertex_of)[a], b = (*vertex_of)[b];
      half.push_back({(uint64_t(std::min(a, b)) << 32) | std::max(a, b), j, k, a < b});
    }
  std::sort(half.begin(), half.end(), [](const HalfEdge& x, const HalfEdge& y) {
    return x.key < y.key || (x.key == y.key && x.face < y.face);
  });
  std::vector<uint32_t> parent(3 * nf);
  for (uint32_t i = 0; i < parent.size(); ++i) parent[i] = i;
  m.neighbours.assign(nf, {});
  for (size_t i = 0; i < half.size();) {
    size_t e = i;
    while (e < half.size() && half[e].key == half[i].key) ++e;
    if (e - i == 2 && half[i].forward != half[i + 1].forward && half[i].face != half[i + 1].face) {
      const HalfEdge &x = half[i], &y = half[i + 1];
      // x runs p -> q, y runs q -> p: x's start meets y's end and back.
      const uint32_t x0 = 3 * x.face + x.k, x1 = 3 * x.face + (x.k + 1) % 3;
      const uint32_t y0 = 3 * y.face + y.k, y1 = 3 * y.face + (y.k + 1) % 3;
      parent[find(parent, x0)] = find(parent, y1);
      parent[find(parent, x1)] = find(parent, y0);
      m.neighbours[x.face].push_back(y.face);
      m.neighbours[y.face].push_back(x.face);
    }
    i = e;
  }
  std::vector<uint32_t> local(3 * nf, UINT32_MAX);
  uint32_t nv = 0;
  m.triangles.resize(nf);
  for (uint32_t c = 0; c < 3 * nf; ++c) {
    const uint32_t r = find(parent, c);
    if (local[r] == UINT32_MAX) local[r] = nv++;
    m.triangles[c / 3][c % 3] = local[r];
  }
  atlas::ChartMesh& ch = m.chart;
  ch.faces.assign(tris.begin(), tris.end());
  ch.tri.resize(nf);
  ch.vertex_global.assign(nv, -1);
  ch.position.assign(nv, Vec3{0, 0, 0});
  std::vector<int> uses(nv, 0);
  m.rest.resize(nf);
  for (uint32_t j = 0; j < nf; ++j) {
    for (int k = 0; k < 3; ++k) {
      const uint32_t v = m.triangles[j][k];
      ch.tri[j][k] = int(v);
      ch.position[v] = ch.position[v] + soup.corner(tris[j], k);
      ++uses[v];
    }
    m.rest[j] = transfer::detail::rest_triangle(soup.corner(tris[j], 0), soup.corner(tris[j], 1),
                                                soup.corner(tris[j], 2), uv_per_length, 1.0);
  }
  for (uint32_t v = 0; v < nv; ++v) ch.position[v] = (1.0 / std::max(1, uses[v])) * ch.position[v];
  // Components through joined edges.
  m.component.assign(nf, UINT32_MAX);
  for (uint32_t s = 0; s < nf; ++s) {
    if (m.component[s] != UINT32_MAX) continue;
    std::vector<uint32_t> stack{s};
    m.component[s] = m.components;
    while (!stack.empty()) {
      const uint32_t i = stack.back();
      stack.pop_back();
      for (uint32_t j : m.neighbours[i])
        if (m.component[j] == UINT32_MAX) m.component[j] = m.components, stack.push_back(j);
    }
    ++m.components;
  }
  // Boundary loops (each boundary vertex has one outgoing boundary
  // half-edge, the corner joins above make sure of it), Euler characteristic.
  std::vector<int64_t> next(nv, -1);
  size_t boundary_half_edges = 0;
  for (size_t i = 0; i < half.size();) {
    size_t e = i;
    while (e < half.size() && half[e].key == half[i].key) ++e;
    const bool interior = e - i == 2 && half[i].forward != half[i + 1].forward && half[i].face != half[i + 1].face;
    if (!interior)
      for (size_t h = i; h < e; ++h) {
        const uint32_t a = m.triangles[half[h].face][half[h].k], b = m.triangles[half[h].face][(half[h].k + 1) % 3];
        ++boundary_half_edges;
        if (next[a] >= 0) next[a] = -2;  // two boundary edges leave a: not a disk-like vertex
        else if (next[a] == -1) next[a] = b;
      }
    i = e;
  }
  const size_t edges = (3 * nf + boundary_half_edges) / 2;
  ch.euler = int(nv) - int(edges) + int(nf);
  ch.boundary_loops = 0;
  ch.boundary.clear();
  std::vector<uint8_t> seen(nv, 0);
  for (uint32_t v = 0; v < nv; ++v) {
    if (next[v] == -2) {
      ch.boundary_loops = -1;
      break;
    }
    if (next[v] < 0 || seen[v]) continue;
    std::vector<int> loop;
    int64_t w = v;
    for (; w >= 0 && !seen[w]; w = next[w]) {
      seen[w] = 1;
      loop.push_back(int(w));
    }
    if (w < 0) {
      ch.boundary_loops = -1;
      break;
    }
    ++ch.boundary_loops;
    if (loop.size() > ch.boundary.size()) ch.boundary = std::move(loop);
  }
  return m;
}

bool flattenable(const atlas::ChartMesh& c) { return c.boundary_loops >= 1 && c.euler + c.boundary_loops == 2; }

Outcome flatten(const PieceMesh& m, const std::vector<uint32_t>& tris, double cell, double max_stretch,
                int solve_iterations, Piece& out, double* stretch_floor) {
  const atlas::ChartMesh& c = m.chart;
  if (!flattenable(c)) return Outcome::topology;
  std::vector<Vec2> uv = atlas::lscm(c);
  if (uv.empty()) return Outcome::flip;
  // LSCM's orientation is free: mirror to the soup's, then match the rest area.
  double signed_area = 0, rest_area = 0;
  for (size_t j = 0; j < m.triangles.size(); ++j) {
    const auto& t = m.triangles[j];
    signed_area += 0.5 * cross(uv[t[1]] - uv[t[0]], uv[t[2]] - uv[t[0]]);
    rest_area += m.rest[j].area;
  }
  if (!(std::abs(signed_area) > 0) || !(rest_area > 0)) return Outcome::flip;
  const double s = std::sqrt(rest_area / std::abs(signed_area));
  for (Vec2& p : uv) p = {(signed_area < 0 ? -s : s) * p.x, s * p.y};
  const std::vector<uint8_t> fixed(uv.size(), 0);
  transfer::detail::SlimOptions so;
  so.max_iterations = solve_iterations;
  bool hopeless = false;
  double floor = 1;             // the stretch heading, when hopeless
  std::vector<double> stretch;  // after iterations kProbeIterations - 2, ...
  so.stop_after = [&](int iterations, const std::vector<Vec2>& now) {
    if (iterations >= solve_iterations || iterations < kProbeIterations - 2) return false;
    stretch.push_back(rest_stretch_l2(m.rest, corners_of(m, now)));
    if (iterations < kProbeIterations) return false;
    const size_t n = stretch.size();
    const double now_stretch = stretch[n - 1];
    const double rate = std::max({0.0, stretch[n - 2] - stretch[n - 1], stretch[n - 3] - stretch[n - 2]});
    floor = std::max(1.0, now_stretch - rate * (solve_iterations - iterations));
    if (iterations == kProbeIterations && now_stretch > kHopelessStretch * max_stretch) return hopeless = true;
    hopeless = floor > max_stretch;
    return hopeless;
  };
  if (!transfer::detail::slim_relax(m.triangles, m.rest, fixed, uv, so).started) {
    // A conformal map of a noisy piece can fold a sliver; ARAP from it
    // often opens the fold (its energy is finite on flipped triangles).
    uv = atlas::arap(c, std::move(uv), 10);
    if (uv.empty() || !transfer::detail::slim_relax(m.triangles, m.rest, fixed, uv, so).started)
      return Outcome::flip;
  }
  if (hopeless) {
    if (stretch_floor) *stretch_floor = floor;
    return Outcome::stretch;
  }
  return judge_piece(m, tris, std::move(uv), cell, max_stretch, out, stretch_floor);
}

Outcome judge_piece(const PieceMesh& m, const std::vector<uint32_t>& tris, std::vector<Vec2> uv, double cell,
                    double max_stretch, Piece& out, double* stretch_floor) {
  // The stretch against each soup triangle's own shape (its rest
  // triangle): the piece's vertices are means of joined noisy corners, and
  // a sliver's mean triangle can differ from the soup's far more than the
  // map does.
  const std::vector<std::array<Vec2, 3>> corners = corners_of(m, uv);
  double area = 0;
  for (const auto& p : corners) area += 0.5 * std::abs(cross(p[1] - p[0], p[2] - p[0]));
  if (const double l2 = rest_stretch_l2(m.rest, corners); l2 > max_stretch) {
    if (stretch_floor) *stretch_floor = l2;
    return Outcome::stretch;
  }
  // The lap test is a share of the piece's samples, so a large piece is
  // sampled no finer than kMaxLapSamples over its area: at that count the
  // share's sampling error is far below kLapShare, while the texel-rate
  // grid made re-flattening a union with a large island (a table top) cost
  // more than its SLIM (docs/tuning.md, session 33).
  const double lap_cell = std::max(cell, std::sqrt(area / kMaxLapSamples));
  if (double(overlap_samples(corners, lap_cell)) > kLapShare * area / (lap_cell * lap_cell)) {
    out.tris = tris;
    out.corner = m.triangles;
    out.uv = std::move(uv);
    return Outcome::overlap;
  }
  out.tris = tris;
  out.corner = m.triangles;
  out.uv = std::move(uv);
  return Outcome::kept;
}

void join_across(const geometry::AdjacentPair& p, uint32_t t, const UvLayout& L, std::vector<uint32_t>& vertex_of,
                 std::vector<uint32_t>& touched) {
  const bool t_is_a = p.a == t;
  const uint32_t o = t_is_a ? p.b : p.a;
  for (int s = 0; s < 2; ++s) {
    const uint32_t mine = L.corner_vertex[t][t_is_a ? p.a_corner[s] : p.b_corner[s]];
    const uint32_t theirs = L.corner_vertex[o][t_is_a ? p.b_corner[s] : p.a_corner[s]];
    if (vertex_of[mine] != mine) continue;  // joined already
    vertex_of[mine] = theirs;
    touched.push_back(mine);
  }
}

size_t flatten_cost(size_t size) {
  return size_t(double(size) * std::max(1.0, std::sqrt(double(size) / kFlattenCostKnee)));
}

}  // namespace soupuv::uvsolve::detail
