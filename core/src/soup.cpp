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

std::string geometry_hash(const Soup& soup) {
  Hasher h;
  h.add(soup.triangles.size());
  for (const Tri& t : soup.triangles)
    for (uint32_t v : t) h.add(soup.positions[v]);
  return h.hex();
}

namespace {
struct Vec3BitsHash {
  size_t operator()(const Vec3& p) const {
    Hasher h;
    h.add(p);
    return std::hash<std::string>()(h.hex());
  }
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
