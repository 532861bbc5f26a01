// Internal pieces of the GLB writer (soupuv/io/write.h), one file each:
//   gltf_write_nodes.cpp     output node tree, instance placement, corner positions
//   gltf_write_weld.cpp      grouping triangles per (node, mesh, primitive); welding
//   gltf_write_materials.cpp materials with our baseColorTexture
//   gltf_write_skins.cpp     skins re-pointed at the output nodes
//   gltf_write_glb.cpp       BIN chunk assembly and the GLB container
//   draco_encode.cpp         KHR_draco_mesh_compression payloads
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "soupuv/io/asset.h"
#include "soupuv/vec.h"

namespace soupuv::io::detail {

using Float3 = std::array<float, 3>;

// Which mesh instance every soup triangle belongs to. The loader's
// Asset::instances when present; otherwise derived from the origins, one
// instance per (node, mesh) with the node's world matrix.
struct InstanceTable {
  std::vector<uint32_t> triangle_instance;
  std::vector<MeshInstance> instances;
};
InstanceTable instance_table(const Asset& asset);

// The output node hierarchy: the source scenes expanded into strict trees
// (glTF requires one parent per node; a source node reached along several
// paths, as in CubeScaledInstances, becomes one output node per path). Node
// fields kept: name, matrix/TRS, camera, extras; meshes attached later.
struct NodeTree {
  nlohmann::json nodes = nlohmann::json::array();
  nlohmann::json scenes = nlohmann::json::array();
  int scene = 0;
  std::vector<int32_t> source_node;  // per output node
  std::vector<Mat4> world;           // per output node
};
NodeTree expand_node_tree(const nlohmann::json& document);

// The output node each instance's mesh goes on: the path of its source node
// whose world matrix is closest to the instance's. An instance with no such
// path (a raw .drc, or a node outside every scene) gets a new root node in the
// default scene carrying the instance's world matrix.
std::vector<int32_t> place_instances(NodeTree& tree, const std::vector<MeshInstance>& instances);

// Position of every soup corner (3 per triangle) in its instance's frame.
// Taken from asset.local_positions when present (bit-exact); otherwise derived
// by inverting the instance's world matrix, with a warning.
std::vector<Float3> corner_positions(const Asset& asset, const InstanceTable& table,
                                     std::vector<std::string>& warnings);

// One output primitive: welded vertices (equal position AND uv bits share a
// vertex) and 3 indices per triangle, in the source primitive's triangle order.
struct OutPrimitive {
  int32_t source_primitive = 0;
  int32_t material = -1;  // source material index, -1: default material
  std::vector<float> positions;  // xyz per vertex
  std::vector<float> uvs;        // uv per vertex
  std::vector<float> normals;    // xyz per vertex, or empty
  std::vector<float> colors;     // COLOR_0 rgba per vertex, or empty
  // The source's TEXCOORD_n (written as TEXCOORD_n+1): (n, uv per vertex).
  std::vector<std::pair<int, std::vector<float>>> texcoords;
  // The source's JOINTS_n / WEIGHTS_n, sets 0..k-1 (glTF wants them numbered
  // without gaps), written under the same names: 4 values per vertex each.
  struct SkinSet {
    std::vector<uint16_t> joints;
    std::vector<float> weights;
  };
  std::vector<SkinSet> skin_sets;
  std::vector<uint32_t> indices;
  size_t vertex_count() const { return positions.size() / 3; }
};

// Whether a skin set's joint indices all fit UNSIGNED_BYTE (the writer then
// uses it, half the bytes of UNSIGNED_SHORT; the values are the same).
inline bool joints_fit_bytes(const std::vector<uint16_t>& joints) {
  for (uint16_t j : joints)
    if (j > 255) return false;
  return true;
}

// One output mesh per mesh instance.
struct OutMesh {
  uint32_t instance = 0;     // index into InstanceTable::instances
  int32_t source_mesh = 0;
  std::vector<OutPrimitive> primitives;
};

// What build_meshes counts while it welds.
struct BuildCounts {
  size_t nonfinite_uvs = 0;       // corner UVs written as (0,0)
  size_t degenerate_normals = 0;  // flat normals of float-degenerate triangles (+z)
  size_t replaced_normals = 0;    // source NORMALs zero or non-finite: the flat normal written
  size_t normalized_weights = 0;  // output vertices whose source weights did not sum to 1 (normalized)
};

// Groups soup triangles by origin and welds their corners. Non-finite UVs are
// written as (0,0). With flat_normals every corner carries its triangle's unit
// normal (triangles degenerate in float get +z); otherwise a primitive whose
// source had NORMAL keeps it (normalized). With keep_colors, COLOR_0 is kept;
// the source's TEXCOORD_n always are, and so are JOINTS_n/WEIGHTS_n on the
// instances marked in skinned_instances. Corners weld only where all agree.
std::vector<OutMesh> build_meshes(const Asset& asset, const InstanceTable& table,
                                  std::span<const Float3> corner_positions,
                                  std::span<const Vec2> corner_uvs, bool flat_normals, bool keep_colors,
                                  const std::vector<bool>& skinned_instances, BuildCounts& counts);

// The output skins. A source skin is kept when its inverse bind matrices were
// read and each of its joints, and its skeleton, is exactly one output node:
// a joint the node-tree expansion copied onto several paths (a node with
// several parents) or left out (in no scene) has no single node to name, so
// that skin is dropped with a warning saying which node. The JSON keeps name,
// extras, joints and skeleton (re-numbered); inverseBindMatrices is set by the
// caller, which owns the accessors.
struct SkinPlan {
  std::vector<int32_t> output_skin;  // per source skin: its output index, -1 when dropped
  nlohmann::json skins = nlohmann::json::array();
  std::vector<int32_t> source_skin;  // per output skin
};
SkinPlan plan_skins(const Asset& asset, const NodeTree& tree, std::vector<std::string>& warnings);

// The source skin of a node (its "skin"), or -1 when it has none or names none of the document's skins.
int32_t node_skin(const nlohmann::json& document, int32_t node);


// The document's materials with baseColorTexture set to texture_index on
// TEXCOORD_0 and everything that referred to the old UVs dropped (warned once
// per kind). Appends a default material when needs_default; its index is the
// returned array's last.
nlohmann::json write_materials(const nlohmann::json& document, int texture_index,
                               bool needs_default, std::vector<std::string>& warnings);

// Accumulates the BIN chunk; every view starts 4-byte aligned.
class BinBuilder {
 public:
  // Appends bytes and returns the index of a new bufferView over them.
  int add_view(std::span<const uint8_t> bytes, int target /* 0: none */);
  nlohmann::json views() const { return views_; }
  const std::vector<uint8_t>& data() const { return data_; }

 private:
  std::vector<uint8_t> data_;
  nlohmann::json views_ = nlohmann::json::array();
};

// GLB container: header, JSON chunk (space-padded), BIN chunk (zero-padded).
std::vector<uint8_t> pack_glb(const nlohmann::json& document, const std::vector<uint8_t>& bin);

// A Draco-encoded primitive and what its accessors must say.
struct DracoPrimitive {
  std::vector<uint8_t> bytes;
  int position_id = -1;  // Draco attribute unique ids, for the extension object
  int texcoord_id = -1;
  int normal_id = -1;    // -1 when the primitive has no normals
  // Further attributes (COLOR_0, TEXCOORD_1.., JOINTS_n, WEIGHTS_n) and what
  // their accessors must say the decoder gives.
  struct Extra {
    std::string name;
    int id = -1;              // Draco unique id
    int component_type = 0;   // glTF componentType
    const char* type = "";    // glTF accessor type
  };
  std::vector<Extra> extra_ids;
  size_t points = 0;     // vertex count after decoding (the accessors' count)
  size_t faces = 0;
};

// Encodes positions + UVs (+ normals when present; quantization bits 0 = lossless) and decodes the
// result once to learn the counts the decoder will produce.
DracoPrimitive draco_encode(const OutPrimitive& primitive, int position_bits, int texcoord_bits);

}  // namespace soupuv::io::detail
