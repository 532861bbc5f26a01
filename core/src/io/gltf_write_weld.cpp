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
#include "io/skin_weights.h"
#include "soupuv/errors.h"

namespace soupuv::io::detail {

namespace {

// Bit patterns of everything a written vertex carries: position, UV, normal
// (zero when not written: -0.0 and 0.0 stay distinct, as in the source), then
// colour, the source UV sets and the skin sets when the primitive keeps them.
using CornerKey = std::vector<uint32_t>;

struct CornerKeyHash {
  size_t operator()(const CornerKey& k) const {
    uint64_t h = 1469598103934665603ull;  // FNV-1a over the words
    for (uint32_t b : k) h = (h ^ b) * 1099511628211ull;
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
                                  std::span<const Vec2> corner_uvs, bool flat_normals, bool keep_colors,
                                  const std::vector<bool>& skinned_instances, BuildCounts& counts) {
  const Soup& soup = asset.soup;
  const VertexAttributes& attrs = asset.attributes;
  // instance -> primitive -> triangles; std::map keeps the output order
  // deterministic and close to the source's.
  std::map<uint32_t, std::map<int32_t, std::vector<uint32_t>>> groups;
  for (size_t t = 0; t < soup.triangles.size(); ++t)
    groups[table.triangle_instance[t]][soup.origins[t].primitive].push_back(static_cast<uint32_t>(t));

  counts = {};
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
      // One source primitive: its vertices all have the same attributes.
      const uint32_t present = attrs.present.empty() ? 0 : attrs.present[soup.triangles[triangles.front()][0]];
      const bool source_normals = !flat_normals && (present & VertexAttributes::kNormal);
      const bool colors = keep_colors && (present & VertexAttributes::kColor);
      for (int n = 0; n < int(attrs.texcoords.size()); ++n)
        if (present & VertexAttributes::texcoord_bit(n)) out.texcoords.push_back({n, {}});
      // Skin sets from 0 up to the first the primitive lacks: a later set
      // alone would leave a gap in the numbering, which glTF forbids.
      if (key < skinned_instances.size() && skinned_instances[key])
        for (int n = 0; n < int(attrs.joints.size()) && (present & VertexAttributes::skin_bit(n)); ++n)
          out.skin_sets.emplace_back();
      std::unordered_map<CornerKey, uint32_t, CornerKeyHash> welded;
      welded.reserve(triangles.size() * 3);
      out.indices.reserve(triangles.size() * 3);
      CornerKey ck;
      for (uint32_t t : triangles) {
        Float3 flat{0, 0, 0};
        size_t degenerate_fallback = 0;  // a source normal's fallback: counted when used
        if (flat_normals || source_normals)
          flat = flat_normal(corner_positions[t * 3], corner_positions[t * 3 + 1], corner_positions[t * 3 + 2],
                             flat_normals ? counts.degenerate_normals : degenerate_fallback);
        for (int k = 0; k < 3; ++k) {
          const uint32_t v = soup.triangles[t][k];
          const Float3& p = corner_positions[t * 3 + k];
          Vec2 uv = corner_uvs[t * 3 + k];
          if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) {
            uv = {0, 0};
            ++counts.nonfinite_uvs;
          }
          float u = static_cast<float>(uv.x), w = static_cast<float>(uv.y);
          Float3 normal = flat_normals ? flat : Float3{0, 0, 0};
          if (source_normals) {
            const auto& sn = attrs.normals[v];
            Vec3 n = normalized(Vec3{sn[0], sn[1], sn[2]});
            if (std::isfinite(n.x) && std::isfinite(n.y) && std::isfinite(n.z) && norm(n) > 0.5)
              normal = {float(n.x), float(n.y), float(n.z)};
            else {
              normal = flat;
              ++counts.replaced_normals;
            }
          }
          ck.assign({bits_of(p[0]), bits_of(p[1]), bits_of(p[2]), bits_of(u), bits_of(w), bits_of(normal[0]),
                     bits_of(normal[1]), bits_of(normal[2])});
          std::array<float, 4> color{};
          if (colors) {
            for (int c = 0; c < 4; ++c) {
              float x = attrs.colors[v][c];
              color[c] = std::isfinite(x) ? std::clamp(x, 0.0f, 1.0f) : 1.0f;
              ck.push_back(bits_of(color[c]));
            }
          }
          for (auto& [n, values] : out.texcoords)
            for (int c = 0; c < 2; ++c) {
              float x = attrs.texcoords[n][v][c];
              ck.push_back(bits_of(std::isfinite(x) ? x : 0.0f));
            }
          std::array<std::array<float, 4>, VertexAttributes::kMaxSkinSets> weights;
          const std::span<std::array<float, 4>> vertex_weights(weights.data(), out.skin_sets.size());
          for (size_t n = 0; n < out.skin_sets.size(); ++n) weights[n] = attrs.weights[n][v];
          const bool normalized = normalize_skin_weights(vertex_weights);
          for (size_t n = 0; n < out.skin_sets.size(); ++n)
            for (int c = 0; c < 4; ++c) ck.insert(ck.end(), {attrs.joints[n][v][c], bits_of(weights[n][c])});
          auto [it, inserted] = welded.try_emplace(ck, static_cast<uint32_t>(out.vertex_count()));
          if (inserted) {
            out.positions.insert(out.positions.end(), {p[0], p[1], p[2]});
            out.uvs.insert(out.uvs.end(), {u, w});
            if (flat_normals || source_normals) out.normals.insert(out.normals.end(), normal.begin(), normal.end());
            if (colors) out.colors.insert(out.colors.end(), color.begin(), color.end());
            for (auto& [n, values] : out.texcoords)
              for (int c = 0; c < 2; ++c) {
                float x = attrs.texcoords[n][v][c];
                values.push_back(std::isfinite(x) ? x : 0.0f);
              }
            // Skinning values are copied as read (the source's skin gave them
            // their meaning), weights normalized only where glTF requires it.
            for (size_t n = 0; n < out.skin_sets.size(); ++n) {
              out.skin_sets[n].joints.insert(out.skin_sets[n].joints.end(), attrs.joints[n][v].begin(),
                                             attrs.joints[n][v].end());
              out.skin_sets[n].weights.insert(out.skin_sets[n].weights.end(), weights[n].begin(), weights[n].end());
            }
            if (normalized) ++counts.normalized_weights;
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
