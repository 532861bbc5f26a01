// The output skins (see gltf_write_parts.h): each source skin re-pointed at
// the output nodes its joints became. The output node tree is the source's
// scenes expanded into strict trees, so a source node usually has exactly one
// output node; a skin is kept only when that holds for every node it names.
// O(output nodes + joints).
#include <map>

#include "gltf_write_parts.h"

namespace soupuv::io::detail {

namespace {

using nlohmann::json;

const json& array_or_empty(const json& document, const char* key) {
  static const json empty = json::array();
  auto it = document.find(key);
  return it != document.end() && it->is_array() ? *it : empty;
}

}  // namespace

int32_t node_skin(const json& document, int32_t node) {
  const json& nodes = array_or_empty(document, "nodes");
  if (node < 0 || static_cast<size_t>(node) >= nodes.size() || !nodes[node].is_object()) return -1;
  auto it = nodes[node].find("skin");
  if (it == nodes[node].end() || !it->is_number_unsigned()) return -1;
  const size_t skin = it->get<size_t>();
  return skin < array_or_empty(document, "skins").size() ? static_cast<int32_t>(skin) : -1;
}

SkinPlan plan_skins(const Asset& asset, const NodeTree& tree, std::vector<std::string>& warnings) {
  const json& skins = array_or_empty(asset.document, "skins");
  SkinPlan plan;
  plan.output_skin.assign(skins.size(), -1);
  // Source node -> its output node, or -1 when it has none or several.
  std::map<int32_t, int32_t> single;
  for (size_t i = 0; i < tree.source_node.size(); ++i) {
    auto [it, inserted] = single.try_emplace(tree.source_node[i], static_cast<int32_t>(i));
    if (!inserted) it->second = -1;
  }
  for (size_t s = 0; s < skins.size(); ++s) {
    if (s >= asset.skins.size()) {  // an Asset not made by the loader
      warnings.push_back("skin " + std::to_string(s) + " dropped: its inverse bind matrices were not loaded");
      continue;
    }
    if (!asset.skins[s].readable) continue;  // the loader said why
    const json& skin = skins[s];
    std::string why;
    auto output_node = [&](const json& source) -> int32_t {
      if (!source.is_number_unsigned()) {
        why = "a joint is not a node index";
        return -1;
      }
      auto it = single.find(static_cast<int32_t>(source.get<uint32_t>()));
      if (it == single.end())
        why = "node " + std::to_string(source.get<uint32_t>()) + " is in no scene";
      else if (it->second < 0)
        why = "node " + std::to_string(source.get<uint32_t>()) +
              " has several parents, so the output (a strict tree) holds several copies of it";
      return it == single.end() ? -1 : it->second;
    };
    json out = json::object();
    for (const char* key : {"name", "extras"})
      if (skin.contains(key)) out[key] = skin[key];
    out["joints"] = json::array();
    bool ok = true;
    for (const json& joint : skin["joints"]) {
      const int32_t node = output_node(joint);
      ok = ok && node >= 0;
      out["joints"].push_back(node);
    }
    if (ok && skin.contains("skeleton")) {
      const int32_t node = output_node(skin["skeleton"]);
      ok = node >= 0;
      out["skeleton"] = node;
    }
    if (!ok) {
      warnings.push_back("skin " + std::to_string(s) + " dropped with its meshes' JOINTS_n/WEIGHTS_n: " + why);
      continue;
    }
    plan.output_skin[s] = static_cast<int32_t>(plan.skins.size());
    plan.source_skin.push_back(static_cast<int32_t>(s));
    plan.skins.push_back(std::move(out));
  }
  return plan;
}

}  // namespace soupuv::io::detail
