#include "soupuv/field/orient.h"

#include <deque>

namespace soupuv::field {

namespace {

// Does triangle t traverse its edge from corner c0 to corner c1 (forward)?
bool forward(uint8_t c0, uint8_t c1) { return (c0 + 1) % 3 == c1; }

}  // namespace

Orientation consistent_orientation(const Soup& soup,
                                   const std::vector<geometry::AdjacentPair>& adjacency) {
  const size_t n = soup.triangles.size();
  // CSR neighbour lists with "same winding needed" per edge: neighbours that
  // traverse the shared edge in opposite directions already agree.
  std::vector<uint32_t> start(n + 1, 0);
  for (const auto& p : adjacency) { ++start[p.a + 1]; ++start[p.b + 1]; }
  for (size_t i = 0; i < n; ++i) start[i + 1] += start[i];
  std::vector<uint32_t> fill(start.begin(), start.end() - 1);
  std::vector<uint32_t> nbr(start[n]);
  std::vector<uint8_t> agree(start[n]);
  for (const auto& p : adjacency) {
    bool opposite = forward(p.a_corner[0], p.a_corner[1]) != forward(p.b_corner[0], p.b_corner[1]);
    nbr[fill[p.a]] = p.b; agree[fill[p.a]++] = opposite;
    nbr[fill[p.b]] = p.a; agree[fill[p.b]++] = opposite;
  }

  Orientation o;
  o.flip.assign(n, 0);
  o.component.assign(n, UINT32_MAX);
  std::deque<uint32_t> queue;
  std::vector<uint32_t> members;
  for (size_t seed = 0; seed < n; ++seed) {
    if (o.component[seed] != UINT32_MAX) continue;
    const uint32_t comp = o.components++;
    members.clear();
    o.component[seed] = comp;
    o.flip[seed] = 1;
    queue.push_back(uint32_t(seed));
    while (!queue.empty()) {
      uint32_t t = queue.front();
      queue.pop_front();
      members.push_back(t);
      for (uint32_t e = start[t]; e < start[t + 1]; ++e) {
        uint32_t u = nbr[e];
        int8_t want = agree[e] ? o.flip[t] : int8_t(-o.flip[t]);
        if (o.component[u] == UINT32_MAX) {
          o.component[u] = comp;
          o.flip[u] = want;
          queue.push_back(u);
        } else if (o.flip[u] != want && u > t) {
          ++o.conflicting_edges;  // counted once per edge (from its smaller end)
        }
      }
    }
    // Keep the input winding of the larger part of the component.
    double kept = 0, reversed = 0;
    for (uint32_t t : members) (o.flip[t] > 0 ? kept : reversed) += triangle_area(soup, t);
    if (reversed > kept)
      for (uint32_t t : members) o.flip[t] = int8_t(-o.flip[t]);
  }
  for (int8_t f : o.flip) o.flipped_triangles += f < 0;
  return o;
}

int line_side(const Soup& soup, const field::FieldLines& lines, size_t line) {
  uint32_t b = lines.offsets[line], e = lines.offsets[line + 1];
  uint32_t c = lines.corner[line];
  Vec3 v = soup.corner(c / 3, c % 3);
  Vec3 n = triangle_normal(soup, c / 3);
  // The first stored point may be the corner itself; the first one that has
  // left it tells the side.
  for (uint32_t j = b; j < e; ++j) {
    double s = dot(lines.points[j] - v, n);
    if (s != 0) return s > 0 ? 1 : -1;
  }
  return 0;
}

SideChoice component_sides(const Soup& soup, const Orientation& orientation,
                           const field::FieldLines& free_lines) {
  SideChoice sc;
  std::vector<double> vote(orientation.components, 0.0);
  for (size_t i = 0; i < free_lines.size(); ++i) {
    uint32_t t = free_lines.corner[i] / 3;
    if (t >= soup.triangles.size()) continue;
    int s = line_side(soup, free_lines, i);
    vote[orientation.component[t]] += s * orientation.flip[t] * triangle_area(soup, t);
  }
  sc.component_side.resize(orientation.components);
  for (uint32_t c = 0; c < orientation.components; ++c) sc.component_side[c] = vote[c] >= 0 ? 1 : -1;
  sc.triangle_side.resize(soup.triangles.size());
  for (size_t t = 0; t < soup.triangles.size(); ++t)
    sc.triangle_side[t] = int8_t(sc.component_side[orientation.component[t]] * orientation.flip[t]);
  sc.mixed_triangles_before = mixed_side_triangles(soup, free_lines);
  return sc;
}

size_t mixed_side_triangles(const Soup& soup, const field::FieldLines& lines) {
  std::vector<int8_t> seen(soup.triangles.size(), 0);  // 0 none, +1/-1 side, 2 mixed
  for (size_t i = 0; i < lines.size(); ++i) {
    uint32_t t = lines.corner[i] / 3;
    if (t >= soup.triangles.size()) continue;
    int s = line_side(soup, lines, i);
    if (s == 0) continue;
    if (seen[t] == 0) seen[t] = int8_t(s);
    else if (seen[t] != s) seen[t] = 2;
  }
  size_t mixed = 0;
  for (int8_t v : seen) mixed += v == 2;
  return mixed;
}

}  // namespace soupuv::field
