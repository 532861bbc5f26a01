#include "io/primitive_geometry.h"

#include <cmath>

#include "io/accessors.h"
#include "io/checked_json.h"
#include "io/draco_decode.h"
#include "io/skin_attributes.h"
#include "soupuv/errors.h"

namespace soupuv::io::detail {
namespace {

constexpr uint64_t kTriangles = 4, kStrip = 5, kFan = 6;

std::string name_of(uint64_t mesh, uint64_t primitive) {
  return "mesh " + std::to_string(mesh) + " primitive " + std::to_string(primitive);
}

// The attributes the output keeps (NORMAL, COLOR_0, TEXCOORD_n) read into
// `out`, per source vertex; the others are named in `warnings` as dropped,
// except the skinning ones, which read_skin_attributes reads.
// An attribute whose count differs from POSITION's is dropped (warned).
void read_kept_attributes(const nlohmann::json& doc, BufferTable& buffers, const nlohmann::json& attributes,
                          size_t vertices, uint64_t max_bytes, const std::string& where, PrimitiveGeometry& out,
                          std::vector<std::string>& warnings) {
  for (auto it = attributes.begin(); it != attributes.end(); ++it) {
    const std::string& name = it.key();
    if (name == "POSITION" || is_skin_attribute(name)) continue;  // skinning: skin_attributes.cpp
    if (!it.value().is_number_unsigned()) fail_input(where + ": attribute " + name.substr(0, 40) + " is not an accessor index");
    const uint64_t accessor = it.value().get<uint64_t>();
    int texcoord = -1;
    if (name.rfind("TEXCOORD_", 0) == 0 && name.size() == 10 && name[9] >= '0' && name[9] < '0' + VertexAttributes::kMaxTexcoords)
      texcoord = name[9] - '0';
    if (name != "NORMAL" && name != "COLOR_0" && texcoord < 0) {
      if (name == "TANGENT")
        warnings.push_back("TANGENT dropped: tangents follow the source UVs, not the new map; recompute them for TEXCOORD_0");
      else
        warnings.push_back("vertex attribute " + name.substr(0, 40) +
                           " dropped (soupuv keeps NORMAL, COLOR_0, TEXCOORD_n, JOINTS_n/WEIGHTS_n)");
      continue;
    }
    uint64_t components = 0;
    std::vector<float> v = read_floats(doc, buffers, accessor, max_bytes, components);
    if (components == 0 || v.size() / components != vertices) {
      warnings.push_back("vertex attribute " + name + " dropped: its count differs from POSITION's");
      continue;
    }
    const bool ok = (name == "NORMAL" && components == 3) || (name == "COLOR_0" && (components == 3 || components == 4)) ||
                    (texcoord >= 0 && components == 2);
    if (!ok) {
      warnings.push_back("vertex attribute " + name + " dropped: unexpected type");
      continue;
    }
    if (name == "NORMAL") {
      out.normals.resize(vertices);
      for (size_t i = 0; i < vertices; ++i) out.normals[i] = {v[3 * i], v[3 * i + 1], v[3 * i + 2]};
      out.present |= VertexAttributes::kNormal;
    } else if (name == "COLOR_0") {
      out.colors.resize(vertices);
      for (size_t i = 0; i < vertices; ++i)
        out.colors[i] = {v[components * i], v[components * i + 1], v[components * i + 2],
                         components == 4 ? v[4 * i + 3] : 1.0f};
      out.present |= VertexAttributes::kColor;
    } else {
      if (out.texcoords.size() <= size_t(texcoord)) out.texcoords.resize(size_t(texcoord) + 1);
      auto& uv = out.texcoords[size_t(texcoord)];
      uv.resize(vertices);
      for (size_t i = 0; i < vertices; ++i) uv[i] = {v[2 * i], v[2 * i + 1]};
      out.present |= VertexAttributes::texcoord_bit(texcoord);
    }
  }
}

template <class T>
void gather(std::vector<T>& values, const std::vector<uint32_t>& kept) {
  if (values.empty()) return;
  std::vector<T> out(kept.size());
  for (size_t i = 0; i < kept.size(); ++i) out[i] = values[kept[i]];
  values = std::move(out);
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

void compact_and_check(std::vector<Vec3>& positions, std::vector<Tri>& triangles, const std::string& where,
                       std::vector<uint32_t>* kept_old) {
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
        if (kept_old) kept_old->push_back(v);
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
    for (auto it = attributes->begin(); it != attributes->end(); ++it)
      if (it.key() != "POSITION")
        warnings.push_back("vertex attribute " + it.key().substr(0, 40) +
                           " of a Draco-compressed primitive dropped (soupuv reads POSITION from Draco)");
    out.positions = std::move(decoded.positions);
    out.triangles = std::move(decoded.triangles);
  } else {
    out.positions = read_positions(doc, buffers, *position_accessor, max_bytes);
    read_kept_attributes(doc, buffers, *attributes, out.positions.size(), max_bytes, where, out, warnings);
    read_skin_attributes(doc, buffers, *attributes, out.positions.size(), max_bytes, where, out, warnings);
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
  std::vector<uint32_t> kept;
  compact_and_check(out.positions, out.triangles,
                    where + " (POSITION accessor " + std::to_string(*position_accessor) + ")", &kept);
  gather(out.normals, kept);
  gather(out.colors, kept);
  for (auto& uv : out.texcoords) gather(uv, kept);
  for (auto& j : out.joints) gather(j, kept);
  for (auto& w : out.weights) gather(w, kept);
  return out;
}

}  // namespace soupuv::io::detail
