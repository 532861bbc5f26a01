#include "io/primitive_geometry.h"

#include <cmath>

#include "io/accessors.h"
#include "io/checked_json.h"
#include "io/draco_decode.h"
#include "soupuv/errors.h"

namespace soupuv::io::detail {
namespace {

constexpr uint64_t kTriangles = 4, kStrip = 5, kFan = 6;

std::string name_of(uint64_t mesh, uint64_t primitive) {
  return "mesh " + std::to_string(mesh) + " primitive " + std::to_string(primitive);
}

}  // namespace

uint64_t triangles_for_mode(uint64_t mode, uint64_t n) {
  if (mode == kTriangles) return n / 3;
  if (mode == kStrip || mode == kFan) return n >= 3 ? n - 2 : 0;
  return 0;
}

Tri expand_triangle(uint64_t mode, uint64_t i) {
  uint32_t k = uint32_t(i);
  if (mode == kStrip)  // the spec's order: odd triangles swap their last two corners
    return Tri{k, k + 1 + k % 2, k + 2 - k % 2};
  if (mode == kFan) return Tri{k + 1, k + 2, 0};
  return Tri{3 * k, 3 * k + 1, 3 * k + 2};
}

void compact_and_check(std::vector<Vec3>& positions, std::vector<Tri>& triangles, const std::string& where) {
  constexpr uint32_t kUnused = UINT32_MAX;
  std::vector<uint32_t> remap(positions.size(), kUnused);
  std::vector<Vec3> kept;
  for (size_t t = 0; t < triangles.size(); ++t)
    for (uint32_t& v : triangles[t]) {
      if (v >= positions.size())
        fail_input(where + ": triangle " + std::to_string(t) + " uses vertex " + std::to_string(v) +
                   " but there are " + std::to_string(positions.size()));
      if (remap[v] == kUnused) {
        const Vec3& p = positions[v];
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
          fail_input(where + ": vertex " + std::to_string(v) + " has a non-finite position");
        remap[v] = uint32_t(kept.size());
        kept.push_back(p);
      }
      v = remap[v];
    }
  positions = std::move(kept);
}

PrimitiveGeometry read_primitive(const nlohmann::json& doc, BufferTable& buffers, uint64_t mesh,
                                 uint64_t primitive, uint64_t max_bytes, uint64_t max_triangles,
                                 std::vector<std::string>& warnings) {
  const std::string where = name_of(mesh, primitive);
  const nlohmann::json& m = element(doc, "meshes", mesh, "node");
  const nlohmann::json* prims = find_member(m, "primitives", "mesh " + std::to_string(mesh));
  if (!prims || !prims->is_array() || primitive >= prims->size())
    fail_input("mesh " + std::to_string(mesh) + " has no primitive " + std::to_string(primitive));
  const nlohmann::json& p = (*prims)[size_t(primitive)];

  PrimitiveGeometry out;
  uint64_t mode = get_opt_uint(p, "mode", where).value_or(kTriangles);
  if (mode > kFan) fail_input(where + ": unknown mode " + std::to_string(mode));
  if (auto material = get_opt_uint(p, "material", where)) {
    element(doc, "materials", *material, where);
    out.material = int32_t(*material);
  }
  if (mode < kTriangles) {
    out.skipped = true;
    return out;
  }
  if (find_member(p, "targets", where))
    warnings.push_back(where + ": morph targets ignored (base shape loaded)");

  const nlohmann::json* attributes = find_member(p, "attributes", where);
  if (!attributes || !attributes->is_object()) fail_input(where + " has no attributes");
  auto position_accessor = get_opt_uint(*attributes, "POSITION", where + ".attributes");
  if (!position_accessor) fail_input(where + " has no POSITION attribute");
  auto indices_accessor = get_opt_uint(p, "indices", where);

  std::vector<uint32_t> indices;
  const nlohmann::json* extensions = find_member(p, "extensions", where);
  const nlohmann::json* draco = extensions ? find_member(*extensions, "KHR_draco_mesh_compression", where) : nullptr;
  if (draco) {
    const std::string dwhere = where + " (KHR_draco_mesh_compression)";
    if (mode != kTriangles && mode != kStrip)
      fail_input(dwhere + ": Draco primitives must be TRIANGLES or TRIANGLE_STRIP");
    const nlohmann::json* ids = find_member(*draco, "attributes", dwhere);
    if (!ids || !ids->is_object()) fail_input(dwhere + " has no attributes");
    uint64_t pos_id = get_uint(*ids, "POSITION", dwhere + ".attributes");
    ViewBytes view = buffers.view(get_uint(*draco, "bufferView", dwhere), dwhere);
    if (pos_id > INT32_MAX) fail_input(dwhere + ": POSITION id out of range");
    DracoMesh decoded = decode_draco(view.bytes, int64_t(pos_id), max_triangles, dwhere);
    // The accessors describe the decoded data; disagreeing counts mean a
    // broken or mismatched payload.
    uint64_t expected_vertices = accessor_count(doc, *position_accessor);
    if (expected_vertices != decoded.positions.size())
      fail_input(dwhere + ": decoded " + std::to_string(decoded.positions.size()) +
                 " vertices but the POSITION accessor says " + std::to_string(expected_vertices));
    if (indices_accessor) {
      uint64_t expected_indices = accessor_count(doc, *indices_accessor);
      if (expected_indices != 3 * decoded.triangles.size())
        fail_input(dwhere + ": decoded " + std::to_string(decoded.triangles.size()) +
                   " triangles but the indices accessor holds " + std::to_string(expected_indices) + " indices");
    }
    // Draco decodes to a triangle list whatever the declared mode.
    out.positions = std::move(decoded.positions);
    out.triangles = std::move(decoded.triangles);
  } else {
    out.positions = read_positions(doc, buffers, *position_accessor, max_bytes);
    if (indices_accessor) {
      indices = read_indices(doc, buffers, *indices_accessor, max_bytes);
    } else {
      if (out.positions.size() > UINT32_MAX) fail_input(where + ": too many vertices");
      indices.resize(out.positions.size());
      for (size_t i = 0; i < indices.size(); ++i) indices[i] = uint32_t(i);
    }
    if (indices.size() > UINT32_MAX)
      throw Error(ErrorCode::limit_exceeded, where + ": more than 2^32 indices");
    uint64_t n = triangles_for_mode(mode, indices.size());
    if (n > max_triangles)
      throw Error(ErrorCode::limit_exceeded, where + ": " + std::to_string(n) + " triangles exceed the limit of " +
                                                 std::to_string(max_triangles));
    out.triangles.resize(size_t(n));
    for (uint64_t t = 0; t < n; ++t) {
      Tri corners = expand_triangle(mode, t);
      for (int k = 0; k < 3; ++k) out.triangles[t][k] = indices[corners[k]];
    }
  }
  out.source_index.resize(out.triangles.size());
  for (size_t t = 0; t < out.triangles.size(); ++t) out.source_index[t] = uint32_t(t);
  compact_and_check(out.positions, out.triangles,
                    where + " (POSITION accessor " + std::to_string(*position_accessor) + ")");
  return out;
}

}  // namespace soupuv::io::detail
