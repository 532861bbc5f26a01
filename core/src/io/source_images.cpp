// Reading base-colour images (see io/source_images.h).
#include "io/source_images.h"

#include "io/checked_json.h"
#include "soupuv/errors.h"

namespace soupuv::io::detail {
namespace {

std::string sniff_mime(const std::vector<uint8_t>& b) {
  if (b.size() >= 8 && b[0] == 0x89 && b[1] == 'P' && b[2] == 'N' && b[3] == 'G') return "image/png";
  if (b.size() >= 3 && b[0] == 0xFF && b[1] == 0xD8 && b[2] == 0xFF) return "image/jpeg";
  return "";
}

// One material's image, or throws Error with the reason.
SourceImage read_one(const json& doc, BufferTable& buffers, const json& info, const std::string& where) {
  SourceImage out;
  const uint64_t texture = get_uint(info, "index", where);
  out.tex_coord = int(get_opt_uint(info, "texCoord", where).value_or(0));
  if (out.tex_coord >= VertexAttributes::kMaxTexcoords) fail_input(where + ": texCoord out of range");
  const json& tex = element(doc, "textures", texture, where);
  if (auto sampler = get_opt_uint(tex, "sampler", where)) {
    const json& s = element(doc, "samplers", *sampler, where);
    out.wrap_s = int(get_opt_uint(s, "wrapS", where).value_or(10497));
    out.wrap_t = int(get_opt_uint(s, "wrapT", where).value_or(10497));
  }
  auto source = get_opt_uint(tex, "source", where);
  if (!source) throw Error(ErrorCode::unsupported, where + ": texture has no PNG/JPEG source");
  const json& image = element(doc, "images", *source, where);
  const std::string iwhere = "image " + std::to_string(*source);
  if (auto uri = get_opt_string(image, "uri", iwhere)) {
    out.bytes = buffers.read_uri(*uri, iwhere);
  } else {
    ViewBytes view = buffers.view(get_uint(image, "bufferView", iwhere), iwhere);
    out.bytes.assign(view.bytes.begin(), view.bytes.end());
  }
  out.mime_type = sniff_mime(out.bytes);
  if (out.mime_type.empty()) throw Error(ErrorCode::unsupported, iwhere + " is not PNG or JPEG");
  return out;
}

}  // namespace

void read_base_color_images(const json& doc, BufferTable& buffers, Asset& asset, std::vector<std::string>& warnings) {
  const size_t n = array_size(doc, "materials");
  for (size_t m = 0; m < n; ++m) {
    const json& material = doc["materials"][m];
    if (!material.is_object() || !material.contains("pbrMetallicRoughness")) continue;
    const json& pbr = material["pbrMetallicRoughness"];
    if (!pbr.is_object() || !pbr.contains("baseColorTexture") || !pbr["baseColorTexture"].is_object()) continue;
    const json& info = pbr["baseColorTexture"];
    const std::string where = "material " + std::to_string(m) + " baseColorTexture";
    try {
      asset.base_color_images[int32_t(m)] = read_one(doc, buffers, info, where);
      if (info.contains("extensions") && info["extensions"].is_object() && info["extensions"].contains("KHR_texture_transform"))
        warnings.push_back(where + ": KHR_texture_transform ignored by the re-bake");
    } catch (const Error& e) {
      warnings.push_back("base-colour image not read (" + std::string(e.what()) + "): the re-bake uses the colour factor");
    }
  }
}

}  // namespace soupuv::io::detail
