// The bitmap packer and its rasteriser against brute force: conservative
// texel coverage equals a polygon/square intersection test, dilation equals
// the Chebyshev neighbourhood, and packed charts keep the padding between
// their exact outlines (segment distances), inside [0,1]^2.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>

#include "atlas/chart_raster.h"
#include "atlas/raster_pack.h"

namespace soupuv::atlas {
namespace {

// A random star-shaped simple polygon around `center` (radii in [r0, r1]).
std::vector<Vec2> star(std::mt19937& rng, Vec2 center, double r0, double r1, int n) {
  std::uniform_real_distribution<double> radius(r0, r1);
  std::vector<Vec2> p;
  for (int i = 0; i < n; ++i) {
    double a = 2 * M_PI * (i + 0.5 * std::uniform_real_distribution<double>(0, 1)(rng)) / n;
    double r = radius(rng);
    p.push_back({center.x + r * std::cos(a), center.y + r * std::sin(a)});
  }
  return p;
}

bool inside(const std::vector<Vec2>& poly, Vec2 q) {
  bool in = false;
  for (size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++)
    if ((poly[i].y > q.y) != (poly[j].y > q.y) &&
        q.x < poly[j].x + (poly[i].x - poly[j].x) * (q.y - poly[j].y) / (poly[i].y - poly[j].y))
      in = !in;
  return in;
}

bool segments_cross(Vec2 a, Vec2 b, Vec2 c, Vec2 d) {
  auto side = [](Vec2 p, Vec2 q, Vec2 r) { return cross(q - p, r - p); };
  return side(a, b, c) * side(a, b, d) <= 0 && side(c, d, a) * side(c, d, b) <= 0;
}

double point_segment(Vec2 p, Vec2 a, Vec2 b) {
  Vec2 d = b - a;
  double t = std::clamp(dot(p - a, d) / std::max(dot(d, d), 1e-300), 0.0, 1.0);
  return norm(p - (a + d * t));
}

double segment_distance(Vec2 a, Vec2 b, Vec2 c, Vec2 d) {
  if (segments_cross(a, b, c, d)) return 0;
  return std::min({point_segment(a, c, d), point_segment(b, c, d), point_segment(c, a, b), point_segment(d, a, b)});
}

// Does the closed texel square [i, i+1] x [j, j+1] meet the polygon?
bool texel_touched(const std::vector<Vec2>& poly, int i, int j) {
  Vec2 corners[4] = {{double(i), double(j)}, {i + 1.0, double(j)}, {i + 1.0, j + 1.0}, {double(i), j + 1.0}};
  for (Vec2 p : poly)
    if (p.x >= i && p.x <= i + 1 && p.y >= j && p.y <= j + 1) return true;
  for (Vec2 c : corners)
    if (inside(poly, c)) return true;
  for (size_t k = 0; k < poly.size(); ++k)
    for (int e = 0; e < 4; ++e)
      if (segments_cross(poly[k], poly[(k + 1) % poly.size()], corners[e], corners[(e + 1) % 4])) return true;
  return false;
}

std::set<std::pair<int, int>> texels(const RowMask& m) {
  std::set<std::pair<int, int>> out;
  for (int r = 0; r < m.height; ++r)
    for (int s = m.first[r]; s < m.first[r + 1]; ++s)
      for (int x = m.spans[s].a; x <= m.spans[s].b; ++x) out.insert({x, r});
  return out;
}

TEST(ChartRaster, CoverageEqualsBruteForce) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 40; ++trial) {
    double r1 = 1 + 12 * std::uniform_real_distribution<double>(0, 1)(rng);
    std::vector<Vec2> poly = star(rng, {r1 + 0.3, r1 + 0.7}, 0.3 * r1, r1, 5 + trial % 20);
    RowMask m = rasterize_outline(poly);
    std::set<std::pair<int, int>> expected;
    for (int j = 0; j < m.height + 2; ++j)
      for (int i = 0; i < m.width + 2; ++i)
        if (texel_touched(poly, i, j)) expected.insert({i, j});
    EXPECT_EQ(texels(m), expected) << "trial " << trial;
    EXPECT_EQ(m.texels, static_cast<long long>(expected.size()));
  }
}

TEST(ChartRaster, DilationIsChebyshevNeighbourhood) {
  std::mt19937 rng(3);
  std::vector<Vec2> poly = star(rng, {9, 9}, 2, 8, 11);
  RowMask m = rasterize_outline(poly);
  for (int r : {0, 1, 2, 3}) {
    std::set<std::pair<int, int>> expected;
    for (auto [x, y] : texels(m))
      for (int dy = -r; dy <= r; ++dy)
        for (int dx = -r; dx <= r; ++dx) expected.insert({x + dx + r, y + dy + r});
    EXPECT_EQ(texels(dilate(m, r)), expected) << "r = " << r;
  }
}

// Random star charts (fan triangulated) packed by the bitmap packer: inside
// the square, and every two charts' outlines at least the padding apart.
// Random star-shaped charts as fans (an interior centre vertex), sized in
// [0.2, 1.2) x `scale`, the first `large` of them 4x larger.
struct Stars {
  std::vector<std::vector<Vec2>> uv;
  std::vector<std::vector<std::array<int, 3>>> tris;
  std::vector<std::vector<int>> outline;
  std::vector<PackChart> charts() {
    std::vector<PackChart> c;
    for (size_t i = 0; i < uv.size(); ++i) c.push_back({&uv[i], &tris[i], &outline[i]});
    return c;
  }
};

Stars stars(int n, int large, unsigned seed) {
  std::mt19937 rng(seed);
  Stars s;
  s.uv.resize(n);
  s.tris.resize(n);
  s.outline.resize(n);
  for (int c = 0; c < n; ++c) {
    double size = (c < large ? 4 : 1) * (0.2 + std::uniform_real_distribution<double>(0, 1)(rng));
    int k = 6 + c % 9;
    s.uv[c] = star(rng, {0, 0}, 0.4 * size, size, k);
    s.uv[c].push_back({0, 0});  // fan centre: an interior vertex, not on the outline
    for (int i = 0; i < k; ++i) {
      s.tris[c].push_back({k, i, (i + 1) % k});
      s.outline[c].push_back(i);
    }
  }
  return s;
}

// Every chart inside [0,1]^2, not mirrored, its outline at least `padding`
// texels from every other's and not nested in it; returns the UV area.
double expect_packed_apart(const Stars& s, int texture, double padding) {
  const size_t n = s.uv.size();
  double area = 0;
  for (size_t c = 0; c < n; ++c) {
    for (const Vec2& p : s.uv[c]) {
      EXPECT_GE(p.x, 0);
      EXPECT_LE(p.x, 1);
      EXPECT_GE(p.y, 0);
      EXPECT_LE(p.y, 1);
    }
    for (const auto& t : s.tris[c]) {
      double a = 0.5 * cross(s.uv[c][t[1]] - s.uv[c][t[0]], s.uv[c][t[2]] - s.uv[c][t[0]]);
      EXPECT_GT(a, 0) << "a turn mirrored chart " << c;
      area += std::fabs(a);
    }
  }
  double closest = INFINITY;
  for (size_t a = 0; a < n; ++a)
    for (size_t b = a + 1; b < n; ++b) {
      const auto& oa = s.outline[a];
      const auto& ob = s.outline[b];
      for (size_t i = 0; i < oa.size(); ++i)
        for (size_t j = 0; j < ob.size(); ++j)
          closest = std::min(closest, segment_distance(s.uv[a][oa[i]], s.uv[a][oa[(i + 1) % oa.size()]],
                                                       s.uv[b][ob[j]], s.uv[b][ob[(j + 1) % ob.size()]]));
      // Disjoint outlines could still nest: test one vertex of each inside the other.
      std::vector<Vec2> pa, pb;
      for (int v : oa) pa.push_back(s.uv[a][v]);
      for (int v : ob) pb.push_back(s.uv[b][v]);
      EXPECT_FALSE(inside(pa, pb[0]) || inside(pb, pa[0])) << a << " and " << b << " nest";
    }
  EXPECT_GE(closest * texture, padding - 1e-9);
  return area;
}

// Packs the stars at 8 turns with `options`' other settings, checks them
// (expect_packed_apart) and returns their utilisation.
double pack_and_check(Stars& s, int texture, double padding, RasterPackOptions options, const char* what) {
  std::vector<PackChart> charts = s.charts();
  options.angles = 8;
  const RasterPackResult r = raster_pack(charts, texture, padding, 0, options);
  EXPECT_GT(r.scale, 0);
  if (!(r.scale > 0)) return 0;
  const double area = expect_packed_apart(s, texture, padding);
  std::printf("%s: utilisation %.3f, %d packings\n", what, area, r.attempts);
  return area;
}

TEST(RasterPack, KeepsPaddingBetweenExactOutlines) {
  Stars s = stars(30, 0, 11);
  const double area = pack_and_check(s, 256, 3, {}, "30 stars at 256 px, 3 px padding");
  EXPECT_GT(area, 0.3);  // a packer that spread charts out would pass the gap test
}

TEST(RasterPack, PilotedLargeChartsKeepThePadding) {
  // Five large charts among 60: the pilot rule places the large ones, the
  // greedy the rest; the layout must be as sound as the greedy's.
  Stars s = stars(60, 5, 7);
  RasterPackOptions options;
  options.max_packings = 4;
  options.variant_packings = 0;
  options.pilot_charts = 8;
  const double area = pack_and_check(s, 256, 2, options, "60 stars (5 large) at 256 px, pilot");
  EXPECT_GT(area, 0.3);
}

TEST(RasterPack, SmallChartsLieAlongTheirRectangle) {
  // One large square and 40 small rectangles 4 x 1 turned by 20 degrees:
  // with small_chart_angles the small ones try only their minimal-area
  // rectangle's pose lying and standing, so each comes out with its sides
  // along the axes (8 turns of 45 degrees from its own pose never would).
  std::vector<std::vector<Vec2>> uvs;
  std::vector<std::vector<std::array<int, 3>>> tris;
  std::vector<std::vector<int>> outlines;
  uvs.push_back({{0, 0}, {30, 0}, {30, 30}, {0, 30}});
  const double a = 20 * M_PI / 180, c = std::cos(a), s = std::sin(a);
  for (int k = 0; k < 40; ++k) {
    std::vector<Vec2> r;
    for (const Vec2& p : {Vec2{0, 0}, Vec2{4, 0}, Vec2{4, 1}, Vec2{0, 1}}) r.push_back({c * p.x - s * p.y, s * p.x + c * p.y});
    uvs.push_back(r);
  }
  std::vector<PackChart> charts;
  for (size_t i = 0; i < uvs.size(); ++i) {
    tris.push_back({{0, 1, 2}, {0, 2, 3}});
    outlines.push_back({0, 1, 2, 3});
  }
  for (size_t i = 0; i < uvs.size(); ++i) charts.push_back({&uvs[i], &tris[i], &outlines[i]});
  RasterPackOptions options;
  options.angles = 8;
  options.small_chart_share = 0.01;  // each rectangle is 4 / 1060 of the area
  options.small_chart_angles = 2;
  const RasterPackResult r = raster_pack(charts, 256, 2, 0, options);
  ASSERT_GT(r.scale, 0);
  for (size_t i = 1; i < uvs.size(); ++i) {
    const Vec2 e = uvs[i][1] - uvs[i][0];
    EXPECT_LT(std::min(std::fabs(e.x), std::fabs(e.y)), 1e-9 * norm(e)) << i;
  }
}

TEST(RasterPack, KeepsUvsWhenItCannotBeat) {
  std::vector<Vec2> uv = {{0, 0}, {1, 0}, {0, 1}};
  std::vector<std::array<int, 3>> tri = {{0, 1, 2}};
  std::vector<int> outline = {0, 1, 2};
  std::vector<PackChart> charts = {{&uv, &tri, &outline}};
  // A triangle of area 1/2 at 1e4 texels per unit is far larger than 256 px.
  RasterPackResult r = raster_pack(charts, 256, 2, 1e4, {});
  EXPECT_EQ(r.scale, 0);
  EXPECT_EQ(uv[1].x, 1.0);
}

TEST(RasterPack, PacksANeedleInsteadOfRunningOutOfMemory) {
  // Two triangles of a strip 2^31 units long and 1 wide (the glTF sample
  // ZeroLengthBufferView): at the scale its area suggests it is millions
  // of texels long; the packer must shrink to where it fits, not rasterise it.
  const double length = 2147483648.0;
  std::vector<Vec2> uv = {{0, 0}, {length, 0}, {length, 1}, {0, 1}};
  std::vector<std::array<int, 3>> tri = {{0, 1, 2}, {0, 2, 3}};
  std::vector<int> outline = {0, 1, 2, 3};
  std::vector<PackChart> charts = {{&uv, &tri, &outline}};
  RasterPackResult r = raster_pack(charts, 256, 2, 0, {});
  ASSERT_GT(r.scale, 0);
  EXPECT_LE(r.scale * length, 256.0 * std::sqrt(2.0));  // turned along the diagonal at most
  for (const Vec2& p : uv) {
    EXPECT_GE(p.x, 0.0);
    EXPECT_LE(p.x, 1.0);
    EXPECT_GE(p.y, 0.0);
    EXPECT_LE(p.y, 1.0);
  }
}

}  // namespace
}  // namespace soupuv::atlas
