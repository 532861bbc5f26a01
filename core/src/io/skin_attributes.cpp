#include "io/skin_attributes.h"

#include <cmath>

#include "io/accessors.h"
#include "io/checked_json.h"
#include "soupuv/errors.h"
#include "soupuv/io/asset.h"

namespace soupuv::io::detail {
namespace {

// The set number n of "JOINTS_n" / "WEIGHTS_n" after `prefix`, or -1.
int set_of(const std::string& name, const std::string& prefix) {
  if (name.rfind(prefix, 0) != 0 || name.size() != prefix.size() + 1) return -1;
  const char c = name.back();
  return c >= '0' && c < '0' + VertexAttributes::kMaxSkinSets ? c - '0' : -1;
}

// One VEC4 attribute as floats, or empty (warned) when it is not one per vertex.
std::vector<float> read_vec4(const nlohmann::json& doc, BufferTable& buffers, const nlohmann::json& index,
                             size_t vertices, uint64_t max_bytes, const std::string& name,
                             std::vector<std::string>& warnings) {
  if (!index.is_number_unsigned()) fail_input("attribute " + name + " is not an accessor index");
  uint64_t components = 0;
  std::vector<float> v = read_floats(doc, buffers, index.get<uint64_t>(), max_bytes, components);
  if (components != 4 || v.size() != 4 * vertices) {
    warnings.push_back("skinning attribute " + name + " dropped: not a VEC4 per vertex");
    return {};
  }
  return v;
}

}  // namespace

bool is_skin_attribute(const std::string& name) {
  return name.rfind("JOINTS_", 0) == 0 || name.rfind("WEIGHTS_", 0) == 0;
}

void read_skin_attributes(const nlohmann::json& doc, BufferTable& buffers, const nlohmann::json& attributes,
                          size_t vertices, uint64_t max_bytes, const std::string& where, PrimitiveGeometry& out,
                          std::vector<std::string>& warnings) {
  for (auto it = attributes.begin(); it != attributes.end(); ++it) {
    const std::string& name = it.key();
    if (name.rfind("JOINTS_", 0) == 0 && set_of(name, "JOINTS_") < 0)
      warnings.push_back("skinning attribute " + name.substr(0, 40) + " dropped (soupuv keeps JOINTS_0..JOINTS_" +
                         std::to_string(VertexAttributes::kMaxSkinSets - 1) + ")");
    const int n = set_of(name, "JOINTS_");
    if (n < 0) continue;
    const std::string weights_name = "WEIGHTS_" + std::to_string(n);
    auto w = attributes.find(weights_name);
    if (w == attributes.end()) {
      warnings.push_back(where + ": " + name + " dropped: it has no " + weights_name);
      continue;
    }
    std::vector<float> j = read_vec4(doc, buffers, it.value(), vertices, max_bytes, name, warnings);
    std::vector<float> wt = read_vec4(doc, buffers, *w, vertices, max_bytes, weights_name, warnings);
    if (j.empty() || wt.empty()) continue;
    // Joint indices are unsigned byte/short integers in valid glTF; anything
    // else cannot be written back as an index, so the pair goes.
    bool integral = true;
    for (float x : j) integral = integral && x >= 0 && x <= 65535 && std::floor(x) == x;
    if (!integral) {
      warnings.push_back("skinning attribute " + name + " dropped: joint indices are not integers in [0, 65535]");
      continue;
    }
    if (out.joints.size() <= size_t(n)) {
      out.joints.resize(size_t(n) + 1);
      out.weights.resize(size_t(n) + 1);
    }
    auto& joints = out.joints[size_t(n)];
    auto& weights = out.weights[size_t(n)];
    joints.resize(vertices);
    weights.resize(vertices);
    for (size_t i = 0; i < vertices; ++i)
      for (int c = 0; c < 4; ++c) {
        joints[i][c] = uint16_t(j[4 * i + c]);
        weights[i][c] = wt[4 * i + c];
      }
    out.present |= VertexAttributes::skin_bit(n);
  }
  // A WEIGHTS_n without its JOINTS_n binds to nothing.
  for (auto it = attributes.begin(); it != attributes.end(); ++it)
    if (const int n = set_of(it.key(), "WEIGHTS_"); n >= 0 && !attributes.contains("JOINTS_" + std::to_string(n)))
      warnings.push_back(where + ": " + it.key() + " dropped: it has no JOINTS_" + std::to_string(n));
    else if (it.key().rfind("WEIGHTS_", 0) == 0 && n < 0)
      warnings.push_back("skinning attribute " + it.key().substr(0, 40) + " dropped (soupuv keeps WEIGHTS_0..WEIGHTS_" +
                         std::to_string(VertexAttributes::kMaxSkinSets - 1) + ")");
}

}  // namespace soupuv::io::detail
