// Grouping soup triangles back into their source primitives, per mesh instance,
// and welding their corners (see gltf_write_parts.h). Corners are welded when
// their written position and UV are bit-identical, so vertices are split
// exactly where the UV mapping (or, with flat normals, the facet) changes. Expected O(corners) with a
// hash map per primitive.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <unordered_map>

#include "gltf_write_parts.h"
#include "soupuv/errors.h"

namespace soupuv::io::detail {

namespace {

// Bit pattern of (x, y, z, u, v, nx, ny, nz) — the normal is zero when not
// written: -0.0 and 0.0 stay distinct, as they are in the source accessor.
struct CornerKey {
  uint32_t bits[8];
  bool operator==(const CornerKey& o) const { return std::memcmp(bits, o.bits, sizeof bits) == 0; }
};

struct CornerKeyHash {
  size_t operator()(const CornerKey& k) const {
    uint64_t h = 1469598103934665603ull;  // FNV-1a over the five words
    for (uint32_t b : k.bits) h = (h ^ b) * 1099511628211ull;
    return static_cast<size_t>(h ^ (h >> 29));
  }
};

uint32_t bits_of(float f) {
  uint32_t b;
  std::memcpy(&b, &f, sizeof b);
  return b;
}

// Unit normal of a corner triple by its winding, computed in double from the
// written float positions; a triangle degenerate in float gets +z (counted).
Float3 flat_normal(const Float3& a, const Float3& b, const Float3& c, size_t& degenerate) {
  Vec3 pa{a[0], a[1], a[2]}, pb{b[0], b[1], b[2]}, pc{c[0], c[1], c[2]};
  Vec3 n = normalized(cross(pb - pa, pc - pa));
  if (norm(n) == 0) {
    ++degenerate;
    return {0, 0, 1};
  }
  return {static_cast<float>(n.x), static_cast<float>(n.y), static_cast<float>(n.z)};
}

}  // namespace

std::vector<OutMesh> build_meshes(const Asset& asset, const InstanceTable& table,
                                  std::span<const Float3> corner_positions,
                                  std::span<const Vec2> corner_uvs, bool flat_normals,
                                  size_t& nonfinite_uvs, size_t& degenerate_normals) {
  const Soup& soup = asset.soup;
  // instance -> primitive -> triangles; std::map keeps the output order
  // deterministic and close to the source's.
  std::map<uint32_t, std::map<int32_t, std::vector<uint32_t>>> groups;
  for (size_t t = 0; t < soup.triangles.size(); ++t)
    groups[table.triangle_instance[t]][soup.origins[t].primitive].push_back(static_cast<uint32_t>(t));

  nonfinite_uvs = 0;
  degenerate_normals = 0;
  std::vector<OutMesh> meshes;
  for (auto& [key, primitives] : groups) {
    OutMesh mesh;
    mesh.instance = key;
    mesh.source_mesh = table.instances[key].mesh;
    for (auto& [primitive_index, triangles] : primitives) {
      // Source triangle order, so the output reads like the input.
      std::stable_sort(triangles.begin(), triangles.end(), [&](uint32_t a, uint32_t b) {
        return soup.origins[a].source_index < soup.origins[b].source_index;
      });
      OutPrimitive out;
      out.source_primitive = primitive_index;
      out.material = soup.origins[triangles.front()].material;
      std::unordered_map<CornerKey, uint32_t, CornerKeyHash> welded;
      welded.reserve(triangles.size() * 3);
      out.indices.reserve(triangles.size() * 3);
      for (uint32_t t : triangles) {
        Float3 normal{0, 0, 0};
        if (flat_normals)
          normal = flat_normal(corner_positions[t * 3], corner_positions[t * 3 + 1],
                               corner_positions[t * 3 + 2], degenerate_normals);
        for (int k = 0; k < 3; ++k) {
          const Float3& p = corner_positions[t * 3 + k];
          Vec2 uv = corner_uvs[t * 3 + k];
          if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) {
            uv = {0, 0};
            ++nonfinite_uvs;
          }
          float u = static_cast<float>(uv.x), v = static_cast<float>(uv.y);
          CornerKey ck{{bits_of(p[0]), bits_of(p[1]), bits_of(p[2]), bits_of(u), bits_of(v),
                        bits_of(normal[0]), bits_of(normal[1]), bits_of(normal[2])}};
          auto [it, inserted] = welded.try_emplace(ck, static_cast<uint32_t>(out.vertex_count()));
          if (inserted) {
            out.positions.insert(out.positions.end(), {p[0], p[1], p[2]});
            out.uvs.insert(out.uvs.end(), {u, v});
            if (flat_normals) out.normals.insert(out.normals.end(), normal.begin(), normal.end());
          }
          out.indices.push_back(it->second);
        }
      }
      mesh.primitives.push_back(std::move(out));
    }
    meshes.push_back(std::move(mesh));
  }
  return meshes;
}

}  // namespace soupuv::io::detail
