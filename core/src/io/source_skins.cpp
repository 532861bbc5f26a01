#include "io/source_skins.h"

#include "io/accessors.h"
#include "soupuv/errors.h"

namespace soupuv::io::detail {

std::vector<SourceSkin> read_source_skins(const nlohmann::json& doc, BufferTable& buffers, uint64_t max_bytes,
                                          std::vector<std::string>& warnings) {
  auto list = doc.find("skins");
  if (list == doc.end() || !list->is_array()) return {};
  std::vector<SourceSkin> skins(list->size());
  for (size_t s = 0; s < list->size(); ++s) {
    const nlohmann::json& skin = (*list)[s];
    const std::string where = "skin " + std::to_string(s);
    auto unreadable = [&](const std::string& why) {
      skins[s].readable = false;
      skins[s].inverse_bind_matrices.clear();
      warnings.push_back(where + " dropped: " + why);
    };
    if (!skin.is_object() || !skin.contains("joints") || !skin["joints"].is_array()) {
      unreadable("it has no joints array");
      continue;
    }
    auto ibm = skin.find("inverseBindMatrices");
    if (ibm == skin.end()) continue;  // identity matrices, by the glTF spec
    if (!ibm->is_number_unsigned()) {
      unreadable("inverseBindMatrices is not an accessor index");
      continue;
    }
    uint64_t components = 0;
    try {
      skins[s].inverse_bind_matrices = read_floats(doc, buffers, ibm->get<uint64_t>(), max_bytes, components);
    } catch (const Error& e) {
      // A bad matrix accessor costs the skin, not the mapping of the soup.
      if (e.code() != ErrorCode::invalid_input) throw;
      unreadable(std::string("its inverseBindMatrices cannot be read (") + e.what() + ")");
      continue;
    }
    const size_t joints = skin["joints"].size();
    if (components != 16 || skins[s].inverse_bind_matrices.size() < 16 * joints)
      unreadable("its inverseBindMatrices are not one MAT4 per joint");
    else
      skins[s].inverse_bind_matrices.resize(16 * joints);  // the matrices past the joints are unused
  }
  return skins;
}

}  // namespace soupuv::io::detail
