// Materials of the written GLB (see gltf_write_parts.h): the source materials
// keep their look-defining fields, and baseColorTexture becomes our texture on
// TEXCOORD_0. Textures other than base colour referred to the old UV sets,
// which the output no longer has, so they are dropped — with a warning, since
// a normal map or occlusion map silently vanishing would surprise the user.
#include <set>

#include "gltf_write_parts.h"

namespace soupuv::io::detail {

namespace {

using nlohmann::json;

json base_color_texture(int texture_index) {
  return json{{"index", texture_index}, {"texCoord", 0}};
}

}  // namespace

json write_materials(const json& document, int texture_index, bool needs_default,
                     std::vector<std::string>& warnings) {
  json out = json::array();
  std::set<std::string> dropped_textures, dropped_extensions;
  if (document.contains("materials") && document["materials"].is_array()) {
    for (const json& source : document["materials"]) {
      json m = json::object();
      if (!source.is_object()) {
        out.push_back(json{{"pbrMetallicRoughness",
                            {{"baseColorTexture", base_color_texture(texture_index)}}}});
        continue;
      }
      for (const char* key : {"name", "emissiveFactor", "alphaMode", "alphaCutoff",
                              "doubleSided", "extras"})
        if (source.contains(key)) m[key] = source[key];
      for (const char* key : {"normalTexture", "occlusionTexture", "emissiveTexture"})
        if (source.contains(key)) dropped_textures.insert(key);
      json pbr = json::object();
      if (source.contains("pbrMetallicRoughness") && source["pbrMetallicRoughness"].is_object()) {
        const json& sp = source["pbrMetallicRoughness"];
        for (const char* key : {"baseColorFactor", "metallicFactor", "roughnessFactor", "extras"})
          if (sp.contains(key)) pbr[key] = sp[key];
        if (sp.contains("metallicRoughnessTexture"))
          dropped_textures.insert("metallicRoughnessTexture");
      }
      pbr["baseColorTexture"] = base_color_texture(texture_index);
      m["pbrMetallicRoughness"] = pbr;
      if (source.contains("extensions") && source["extensions"].is_object())
        for (const auto& [name, value] : source["extensions"].items()) dropped_extensions.insert(name);
      out.push_back(m);
    }
  }
  if (needs_default)
    out.push_back(json{{"name", "soupuv default"},
                       {"pbrMetallicRoughness",
                        {{"baseColorTexture", base_color_texture(texture_index)},
                         {"metallicFactor", 0.0}, {"roughnessFactor", 0.8}}}});
  for (const std::string& key : dropped_textures)
    warnings.push_back("material " + key + " dropped: it referred to the source UVs");
  for (const std::string& name : dropped_extensions)
    warnings.push_back("material extension " + name + " dropped");
  return out;
}

}  // namespace soupuv::io::detail
