#include "soupuv/soup.h"

#include <algorithm>
#include <unordered_map>
#include <unordered_set>

#include "soupuv/hash.h"

namespace soupuv {

Box3 bounding_box(const Soup& soup) {
  Box3 box;
  for (const Tri& t : soup.triangles)
    for (uint32_t v : t) box.add(soup.positions[v]);
  return box;
}

double triangle_area(const Soup& soup, size_t t) {
  Vec3 a = soup.corner(t, 0), b = soup.corner(t, 1), c = soup.corner(t, 2);
  return 0.5 * norm(cross(b - a, c - a));
}

Vec3 triangle_normal(const Soup& soup, size_t t) {
  Vec3 a = soup.corner(t, 0), b = soup.corner(t, 1), c = soup.corner(t, 2);
  return normalized(cross(b - a, c - a));
}

double mean_edge_length(const Soup& soup) {
  double sum = 0;
  for (size_t t = 0; t < soup.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) sum += norm(soup.corner(t, k) - soup.corner(t, (k + 1) % 3));
  return soup.triangles.empty() ? 0 : sum / (3.0 * double(soup.triangles.size()));
}

double triangle_perimeter(Vec3 a, Vec3 b, Vec3 c) { return norm(b - a) + norm(c - b) + norm(a - c); }

std::string geometry_hash(const Soup& soup) {
  // The corners' positions in triangle order, so a soup and the same
  // triangles with shared vertices hash alike. A soup stored corner by corner
  // (vertex 3t + k is corner k of triangle t, what the loader makes) is hashed
  // as its position array in one call: the same bytes, the same digest.
  Hasher h;
  h.add(uint64_t(soup.triangles.size()));
  bool corner_order = soup.positions.size() == 3 * soup.triangles.size();
  for (size_t t = 0; corner_order && t < soup.triangles.size(); ++t)
    corner_order = soup.triangles[t] == Tri{uint32_t(3 * t), uint32_t(3 * t + 1), uint32_t(3 * t + 2)};
  if (corner_order) {
    h.add_bytes(soup.positions.data(), soup.positions.size() * sizeof(Vec3));
  } else {
    for (const Tri& t : soup.triangles)
      for (uint32_t v : t) h.add(soup.positions[v]);
  }
  return h.hex();
}

namespace {
struct Vec3BitsHash {
  size_t operator()(const Vec3& p) const { return size_t(hash64(&p, sizeof p)); }
};
struct Vec3BitsEq {
  bool operator()(const Vec3& a, const Vec3& b) const {
    return a.x == b.x && a.y == b.y && a.z == b.z;
  }
};
}  // namespace

SharingStats sharing_stats(const Soup& soup) {
  SharingStats s;
  s.corners = soup.triangles.size() * 3;
  std::unordered_map<uint32_t, uint32_t> uses;  // vertex index -> triangles using it
  std::unordered_set<Vec3, Vec3BitsHash, Vec3BitsEq> positions;
  for (const Tri& t : soup.triangles) {
    for (int k = 0; k < 3; ++k) {
      bool repeated_in_tri = (k > 0 && t[k] == t[0]) || (k > 1 && t[k] == t[1]);
      if (!repeated_in_tri) uses[t[k]]++;
      positions.insert(soup.positions[t[k]]);
    }
  }
  size_t shared = 0;
  for (const Tri& t : soup.triangles)
    for (uint32_t v : t)
      if (uses[v] > 1) ++shared;
  s.distinct_vertex_indices = uses.size();
  s.distinct_positions = positions.size();
  s.shared_index_fraction = s.corners ? double(shared) / double(s.corners) : 0.0;
  s.is_soup = shared == 0;
  return s;
}

}  // namespace soupuv
