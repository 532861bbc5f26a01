// Joining a small island onto a larger one's map (local_join.h): on a flat
// sheet cut into a large island (laid out isometrically) and a strip (laid
// out anywhere), the strip is joined with the large island's UVs untouched
// and no triangle flipped; a large island laid out mirrored is joined in the
// soup's orientation; a strip that touches the large island at one vertex
// only is not joined (its map would be free to turn).
#include "uvsolve/local_join.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numeric>

namespace soupuv {
namespace {

using uvsolve::detail::Outcome;
using uvsolve::detail::UvLayout;

constexpr double kScale = 64.0;  // UV units per unit length

// An n x n sheet in z = 0, counter-clockwise seen from +z. Cells with
// x-index < n - 1 form the large island (layout vertices = the soup's,
// UVs kScale * (+-x, y)); the last column of cells the strip (its own
// layout vertices, UVs shifted and turned away from where they belong).
struct Sheet {
  Soup soup;
  UvLayout layout;
  std::vector<uint32_t> large, strip;  // soup triangles
  std::vector<uint32_t> join;          // layout vertex -> the vertex it is joined to
};

Sheet sheet(int n, bool mirrored, bool strip_touches_one_vertex) {
  Sheet s;
  auto id = [&](int i, int j) { return uint32_t(i * (n + 1) + j); };
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) s.soup.positions.push_back(Vec3{double(i) / n, double(j) / n, 0});
  const uint32_t np = uint32_t(s.soup.positions.size());
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      // The strip: the last column, or (one vertex shared) only its top cell.
      const bool in_strip = i == n - 1 && (!strip_touches_one_vertex || j == n - 1);
      const bool in_large = i < n - 1 && (!strip_touches_one_vertex || j < n - 1);
      if (!in_strip && !in_large) continue;
      const uint32_t p = id(i, j), q = id(i + 1, j), r = id(i + 1, j + 1), w = id(i, j + 1);
      for (const Tri& t : {Tri{p, q, r}, Tri{p, r, w}}) {
        (in_strip ? s.strip : s.large).push_back(uint32_t(s.soup.triangles.size()));
        s.soup.triangles.push_back(t);
        const uint32_t off = in_strip ? np : 0;
        s.layout.corner_vertex.push_back({t[0] + off, t[1] + off, t[2] + off});
        s.layout.island.push_back(in_strip ? 1 : 0);
      }
    }
  s.layout.island_count = 2;
  s.layout.uv.resize(2 * np);
  for (uint32_t v = 0; v < np; ++v) {
    const Vec3 x = s.soup.positions[v];
    s.layout.uv[v] = {kScale * (mirrored ? -x.x : x.x), kScale * x.y};
    s.layout.uv[np + v] = {500 + kScale * x.y, 300 - kScale * x.x};  // the strip, elsewhere
  }
  // The seam: the strip's copies of the large island's vertices join them.
  s.join.resize(2 * np);
  std::iota(s.join.begin(), s.join.end(), 0u);
  std::vector<uint8_t> in_large(np, 0);
  for (uint32_t t : s.large)
    for (uint32_t v : s.soup.triangles[t]) in_large[v] = 1;
  for (uint32_t v = 0; v < np; ++v)
    if (in_large[v]) s.join[np + v] = v;
  return s;
}

struct Joined {
  Outcome outcome;
  uvsolve::detail::Piece piece;
  uvsolve::detail::PieceMesh mesh;
};

Joined join(const Sheet& s) {
  std::vector<uint32_t> tris = s.large;
  tris.insert(tris.end(), s.strip.begin(), s.strip.end());
  Joined j;
  j.mesh = uvsolve::detail::piece_mesh(s.soup, kScale, tris, s.layout, &s.join);
  j.outcome = uvsolve::detail::join_locally(j.mesh, tris, s.large.size(), s.layout, 0.5, 1.25, 10, j.piece);
  return j;
}

double signed_area2(const uvsolve::detail::Piece& p, size_t k) {
  const auto& c = p.corner[k];
  return cross(p.uv[c[1]] - p.uv[c[0]], p.uv[c[2]] - p.uv[c[0]]);
}

TEST(LocalJoin, AStripJoinsWithTheLargeIslandsMapUntouched) {
  const Sheet s = sheet(8, false, false);
  const Joined j = join(s);
  ASSERT_EQ(j.outcome, Outcome::kept);
  ASSERT_EQ(j.piece.corner.size(), s.large.size() + s.strip.size());
  for (size_t k = 0; k < s.large.size(); ++k)
    for (int c = 0; c < 3; ++c) {
      const Vec2 want = s.layout.uv[s.layout.corner_vertex[s.large[k]][c]];
      const Vec2 got = j.piece.uv[j.piece.corner[k][c]];
      EXPECT_EQ(got.x, want.x);
      EXPECT_EQ(got.y, want.y);
    }
  // The strip lands beside the large island, isometrically (the sheet is flat).
  for (size_t k = s.large.size(); k < j.piece.corner.size(); ++k) {
    EXPECT_GT(signed_area2(j.piece, k), 0) << "strip triangle " << k << " flipped";
    for (int c = 0; c < 3; ++c) {
      const Vec3 x = s.soup.positions[s.soup.triangles[s.strip[k - s.large.size()]][c]];
      const Vec2 got = j.piece.uv[j.piece.corner[k][c]];
      EXPECT_NEAR(got.x, kScale * x.x, 1e-6 * kScale);
      EXPECT_NEAR(got.y, kScale * x.y, 1e-6 * kScale);
    }
  }
}

TEST(LocalJoin, AMirroredLargeIslandIsJoinedInTheSoupsOrientation) {
  const Sheet s = sheet(8, true, false);
  const Joined j = join(s);
  ASSERT_EQ(j.outcome, Outcome::kept);
  for (size_t k = 0; k < j.piece.corner.size(); ++k) EXPECT_GT(signed_area2(j.piece, k), 0) << "triangle " << k;
}

TEST(LocalJoin, AStripThatSharesOneVertexIsNotJoined) {
  const Sheet s = sheet(8, false, true);
  EXPECT_EQ(join(s).outcome, Outcome::parts);
}

}  // namespace
}  // namespace soupuv
