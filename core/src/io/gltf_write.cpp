// write_glb (see soupuv/io/write.h): assembles the output document — nodes,
// meshes per node instance, accessors, materials, the texture — around the
// pieces in gltf_write_*.cpp and draco_encode.cpp.
#include <chrono>
#include <cstring>
#include <limits>
#include <set>

#include "gltf_write_parts.h"
#include "soupuv/errors.h"
#include "soupuv/io/write.h"

namespace soupuv::io {

namespace {

using nlohmann::json;
using namespace detail;

constexpr int kArrayBuffer = 34962, kElementArrayBuffer = 34963;
constexpr int kFloat = 5126, kUnsignedByte = 5121, kUnsignedShort = 5123, kUnsignedInt = 5125;
constexpr int kTriangles = 4;

template <class T>
std::span<const uint8_t> as_bytes(const std::vector<T>& v) {
  return {reinterpret_cast<const uint8_t*>(v.data()), v.size() * sizeof(T)};
}

// min/max of float triples, as the accessor's exact float values.
std::pair<json, json> bounds(const std::vector<float>& xyz) {
  float lo[3], hi[3];
  for (int c = 0; c < 3; ++c) {
    lo[c] = std::numeric_limits<float>::infinity();
    hi[c] = -std::numeric_limits<float>::infinity();
  }
  for (size_t i = 0; i < xyz.size(); i += 3)
    for (int c = 0; c < 3; ++c) {
      lo[c] = std::min(lo[c], xyz[i + c]);
      hi[c] = std::max(hi[c], xyz[i + c]);
    }
  return {json{lo[0], lo[1], lo[2]}, json{hi[0], hi[1], hi[2]}};
}

const json& array_or_empty(const json& document, const char* key) {
  static const json empty = json::array();
  auto it = document.find(key);
  return it != document.end() && it->is_array() ? *it : empty;
}

// Skins are kept (plan_skins warns about any it drops); what animates them is not.
void warn_dropped(const json& document, std::vector<std::string>& warnings) {
  if (!array_or_empty(document, "animations").empty())
    warnings.push_back("animations dropped: the output is static (its skins are kept)");
  bool morph = false;
  for (const json& mesh : array_or_empty(document, "meshes"))
    if (mesh.is_object())
      for (const json& p : mesh.value("primitives", json::array()))
        morph = morph || (p.is_object() && p.contains("targets"));
  if (morph) warnings.push_back("morph targets dropped: the output is the static bind pose");
}

std::string node_or_mesh_name(const json& document, const OutMesh& mesh) {
  const json& meshes = array_or_empty(document, "meshes");
  if (mesh.source_mesh >= 0 && static_cast<size_t>(mesh.source_mesh) < meshes.size() &&
      meshes[mesh.source_mesh].is_object() && meshes[mesh.source_mesh].contains("name") &&
      meshes[mesh.source_mesh]["name"].is_string())
    return meshes[mesh.source_mesh]["name"].get<std::string>();
  return "mesh " + std::to_string(mesh.source_mesh);
}

// Gives an output mesh's node its skin: the source node's skin when the
// writer kept it and every primitive carries JOINTS_0 (a skin on a mesh with
// a primitive lacking joints is invalid glTF).
void attach_skin(const json& document, int32_t source_node, const OutMesh& mesh, const SkinPlan& skins,
                 json& node, std::vector<std::string>& warnings) {
  const int32_t skin = node_skin(document, source_node);
  if (skin < 0 || skins.output_skin[skin] < 0) return;
  for (const OutPrimitive& p : mesh.primitives)
    if (p.skin_sets.empty()) {
      warnings.push_back("skin " + std::to_string(skin) + " not attached to node " + std::to_string(source_node) +
                         ": a primitive of its mesh has no JOINTS_0/WEIGHTS_0");
      return;
    }
  node["skin"] = skins.output_skin[skin];
}

struct Builder {
  json accessors = json::array();
  BinBuilder bin;

  int accessor(json a) {
    accessors.push_back(std::move(a));
    return static_cast<int>(accessors.size()) - 1;
  }

  json plain_primitive(const OutPrimitive& p) {
    auto [lo, hi] = bounds(p.positions);
    size_t n = p.vertex_count();
    json attributes;
    attributes["POSITION"] = accessor({{"bufferView", bin.add_view(as_bytes(p.positions), kArrayBuffer)},
                                       {"componentType", kFloat}, {"count", n}, {"type", "VEC3"},
                                       {"min", lo}, {"max", hi}});
    attributes["TEXCOORD_0"] = accessor({{"bufferView", bin.add_view(as_bytes(p.uvs), kArrayBuffer)},
                                         {"componentType", kFloat}, {"count", n}, {"type", "VEC2"}});
    if (!p.normals.empty())
      attributes["NORMAL"] = accessor({{"bufferView", bin.add_view(as_bytes(p.normals), kArrayBuffer)},
                                       {"componentType", kFloat}, {"count", n}, {"type", "VEC3"}});
    if (!p.colors.empty())
      attributes["COLOR_0"] = accessor({{"bufferView", bin.add_view(as_bytes(p.colors), kArrayBuffer)},
                                        {"componentType", kFloat}, {"count", n}, {"type", "VEC4"}});
    for (const auto& [set, values] : p.texcoords)
      attributes["TEXCOORD_" + std::to_string(set + 1)] =
          accessor({{"bufferView", bin.add_view(as_bytes(values), kArrayBuffer)},
                    {"componentType", kFloat}, {"count", n}, {"type", "VEC2"}});
    for (size_t set = 0; set < p.skin_sets.size(); ++set) {
      const auto& [joints, weights] = p.skin_sets[set];
      json joints_accessor = {{"componentType", kUnsignedShort}, {"count", n}, {"type", "VEC4"}};
      if (joints_fit_bytes(joints)) {
        std::vector<uint8_t> narrow(joints.begin(), joints.end());
        joints_accessor["componentType"] = kUnsignedByte;
        joints_accessor["bufferView"] = bin.add_view(narrow, kArrayBuffer);
      } else {
        joints_accessor["bufferView"] = bin.add_view(as_bytes(joints), kArrayBuffer);
      }
      attributes["JOINTS_" + std::to_string(set)] = accessor(joints_accessor);
      attributes["WEIGHTS_" + std::to_string(set)] =
          accessor({{"bufferView", bin.add_view(as_bytes(weights), kArrayBuffer)},
                    {"componentType", kFloat}, {"count", n}, {"type", "VEC4"}});
    }
    int indices;
    // 65535 is the primitive-restart value of unsigned short, so it may not be an index.
    if (n < 65535) {
      std::vector<uint16_t> small(p.indices.begin(), p.indices.end());
      indices = accessor({{"bufferView", bin.add_view(as_bytes(small), kElementArrayBuffer)},
                          {"componentType", kUnsignedShort}, {"count", small.size()}, {"type", "SCALAR"}});
    } else {
      indices = accessor({{"bufferView", bin.add_view(as_bytes(p.indices), kElementArrayBuffer)},
                          {"componentType", kUnsignedInt}, {"count", p.indices.size()}, {"type", "SCALAR"}});
    }
    return json{{"attributes", attributes}, {"indices", indices}, {"mode", kTriangles}};
  }

  json draco_primitive(const OutPrimitive& p, const WriteOptions& options,
                       std::vector<std::string>& warnings) {
    DracoPrimitive d = draco_encode(p, options.draco_position_bits, options.draco_texcoord_bits);
    if (d.faces * 3 != p.indices.size())
      warnings.push_back("Draco dropped " + std::to_string(p.indices.size() / 3 - d.faces) +
                         " degenerate triangle(s)");
    auto [lo, hi] = bounds(p.positions);
    json attributes;
    attributes["POSITION"] = accessor({{"componentType", kFloat}, {"count", d.points},
                                       {"type", "VEC3"}, {"min", lo}, {"max", hi}});
    attributes["TEXCOORD_0"] = accessor({{"componentType", kFloat}, {"count", d.points}, {"type", "VEC2"}});
    if (d.normal_id >= 0)
      attributes["NORMAL"] = accessor({{"componentType", kFloat}, {"count", d.points}, {"type", "VEC3"}});
    for (const DracoPrimitive::Extra& extra : d.extra_ids)
      attributes[extra.name] = accessor({{"componentType", extra.component_type}, {"count", d.points},
                                         {"type", extra.type}});
    int indices = accessor({{"componentType", d.points < 65535 ? kUnsignedShort : kUnsignedInt},
                            {"count", d.faces * 3}, {"type", "SCALAR"}});
    json extension = {{"bufferView", bin.add_view(d.bytes, 0)},
                      {"attributes", {{"POSITION", d.position_id}, {"TEXCOORD_0", d.texcoord_id}}}};
    if (d.normal_id >= 0) extension["attributes"]["NORMAL"] = d.normal_id;
    for (const DracoPrimitive::Extra& extra : d.extra_ids) extension["attributes"][extra.name] = extra.id;
    return json{{"attributes", attributes}, {"indices", indices}, {"mode", kTriangles},
                {"extensions", {{"KHR_draco_mesh_compression", extension}}}};
  }
};

// The vertex attributes the output carries, by glTF name (sorted, once each).
std::vector<std::string> written_attributes(const std::vector<OutMesh>& meshes) {
  std::set<std::string> names = {"POSITION", "TEXCOORD_0"};
  for (const OutMesh& m : meshes)
    for (const OutPrimitive& p : m.primitives) {
      if (!p.normals.empty()) names.insert("NORMAL");
      if (!p.colors.empty()) names.insert("COLOR_0");
      for (const auto& [set, values] : p.texcoords) names.insert("TEXCOORD_" + std::to_string(set + 1));
      for (size_t set = 0; set < p.skin_sets.size(); ++set) {
        names.insert("JOINTS_" + std::to_string(set));
        names.insert("WEIGHTS_" + std::to_string(set));
      }
    }
  return {names.begin(), names.end()};
}

}  // namespace

WriteResult write_glb(const Asset& asset, std::span<const Vec2> corner_uvs,
                      const WriteOptions& options) {
  auto start = std::chrono::steady_clock::now();
  const Soup& soup = asset.soup;
  const json& document = asset.document;
  if (corner_uvs.size() != soup.triangles.size() * 3)
    throw Error(ErrorCode::invalid_input, "writer needs 3 UVs per triangle: got " +
                                              std::to_string(corner_uvs.size()) + " for " +
                                              std::to_string(soup.triangles.size()) + " triangles");
  if (soup.origins.size() != soup.triangles.size())
    throw Error(ErrorCode::invalid_input, "soup has no origin for every triangle");
  if (soup.triangles.empty()) throw Error(ErrorCode::no_triangles, "nothing to write: no triangles");

  WriteResult result;
  warn_dropped(document, result.warnings);
  InstanceTable table = instance_table(asset);
  std::vector<Float3> positions = corner_positions(asset, table, result.warnings);
  NodeTree tree = expand_node_tree(document);
  std::vector<int32_t> placement = place_instances(tree, table.instances);
  SkinPlan skins = plan_skins(asset, tree, result.warnings);
  // An instance keeps its skinning attributes unless its node's skin was
  // dropped: without the skin, joint indices name nothing.
  std::vector<bool> skinned_instances(table.instances.size());
  for (size_t i = 0; i < table.instances.size(); ++i) {
    const int32_t skin = node_skin(document, table.instances[i].node);
    skinned_instances[i] = skin < 0 || skins.output_skin[skin] >= 0;
  }
  BuildCounts counts;
  std::vector<OutMesh> meshes = build_meshes(asset, table, positions, corner_uvs, options.normals,
                                             options.keep_colors, skinned_instances, counts);
  result.nonfinite_uvs = counts.nonfinite_uvs;
  result.degenerate_normals = counts.degenerate_normals;
  if (counts.replaced_normals > 0)
    result.warnings.push_back(std::to_string(counts.replaced_normals) +
                              " source NORMAL(s) were zero or not finite; the triangle's flat normal was written");
  if (counts.normalized_weights > 0)
    result.warnings.push_back(std::to_string(counts.normalized_weights) +
                              " vertices' skin weights did not sum to 1 and were normalized (as glTF requires"
                              " and renderers do on loading); the others are the input's bit for bit");
  result.attributes = written_attributes(meshes);
  if (result.degenerate_normals > 0)
    result.warnings.push_back(std::to_string(result.degenerate_normals) +
                              " triangle(s) are degenerate in float32; their NORMAL is +z");
  if (result.nonfinite_uvs > 0)
    result.warnings.push_back(std::to_string(result.nonfinite_uvs) +
                              " corner UV(s) were not finite and were written as (0,0)");

  json out;
  out["asset"] = {{"version", "2.0"}, {"generator", options.generator}};
  if (document.contains("asset") && document["asset"].is_object() &&
      document["asset"].contains("copyright"))
    out["asset"]["copyright"] = document["asset"]["copyright"];

  Builder builder;
  // The texture first: a single image/sampler/texture shared by every material.
  Texture texture = options.texture ? *options.texture : uv_check_texture(options.check_texture_size);
  int image_view = builder.bin.add_view(texture.bytes, 0);
  out["images"] = json::array({{{"bufferView", image_view}, {"mimeType", texture.mime_type},
                                {"name", !options.texture_name.empty() ? options.texture_name
                                         : options.texture           ? "user texture"
                                                                     : "soupuv UV check"}}});
  out["samplers"] = json::array({{{"magFilter", 9729}, {"minFilter", 9987},
                                  {"wrapS", 10497}, {"wrapT", 10497}}});
  out["textures"] = json::array({{{"sampler", 0}, {"source", 0}}});

  // Primitives without a (valid) source material share one default material.
  const int source_materials = static_cast<int>(array_or_empty(document, "materials").size());
  auto has_source_material = [&](const OutPrimitive& p) {
    return p.material >= 0 && p.material < source_materials;
  };
  bool needs_default = false;
  for (const OutMesh& m : meshes)
    for (const OutPrimitive& p : m.primitives) needs_default = needs_default || !has_source_material(p);
  json materials = write_materials(document, 0, needs_default, result.warnings);
  const int default_material = static_cast<int>(materials.size()) - 1;
  out["materials"] = materials;

  json out_meshes = json::array();
  for (const OutMesh& m : meshes) {
    json mesh = {{"name", node_or_mesh_name(document, m)}, {"primitives", json::array()}};
    for (const OutPrimitive& p : m.primitives) {
      json primitive = options.draco ? builder.draco_primitive(p, options, result.warnings)
                                     : builder.plain_primitive(p);
      primitive["material"] = has_source_material(p) ? p.material : default_material;
      mesh["primitives"].push_back(primitive);
      result.primitives++;
      result.vertices += p.vertex_count();
      result.triangles += p.indices.size() / 3;
    }
    int mesh_index = static_cast<int>(out_meshes.size());
    out_meshes.push_back(mesh);
    tree.nodes[placement[m.instance]]["mesh"] = mesh_index;
    attach_skin(document, table.instances[m.instance].node, m, skins, tree.nodes[placement[m.instance]],
                result.warnings);
  }
  if (!skins.skins.empty()) {
    for (size_t s = 0; s < skins.skins.size(); ++s) {
      const std::vector<float>& matrices = asset.skins[skins.source_skin[s]].inverse_bind_matrices;
      if (matrices.empty()) continue;  // identity, as in the source
      // No target: these are not vertex data (the validator checks).
      skins.skins[s]["inverseBindMatrices"] =
          builder.accessor({{"bufferView", builder.bin.add_view(as_bytes(matrices), 0)},
                            {"componentType", kFloat}, {"count", matrices.size() / 16}, {"type", "MAT4"}});
    }
    out["skins"] = skins.skins;
  }
  result.meshes = out_meshes.size();
  out["meshes"] = out_meshes;
  out["nodes"] = tree.nodes;
  out["scenes"] = tree.scenes;
  out["scene"] = tree.scene;
  if (document.contains("cameras") && document["cameras"].is_array())
    out["cameras"] = document["cameras"];
  out["accessors"] = builder.accessors;
  out["bufferViews"] = builder.bin.views();
  out["buffers"] = json::array({{{"byteLength", builder.bin.data().size()}}});
  if (options.draco) {
    out["extensionsUsed"] = json::array({"KHR_draco_mesh_compression"});
    out["extensionsRequired"] = json::array({"KHR_draco_mesh_compression"});
  }

  result.glb = pack_glb(out, builder.bin.data());
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace soupuv::io
