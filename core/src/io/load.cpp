// io::load_file / io::load_memory: sniff the format, check the container,
// flatten the scene and assemble the soup (see soupuv/io/load.h).
#include "soupuv/io/load.h"

#include <filesystem>
#include <fstream>
#include <algorithm>
#include <map>
#include <new>

#include "io/buffer_table.h"
#include "io/checked_json.h"
#include "io/data_uri.h"
#include "io/draco_decode.h"
#include "io/glb_container.h"
#include "io/primitive_geometry.h"
#include "io/scene_flatten.h"
#include "io/source_skins.h"
#include "io/source_images.h"
#include "soupuv/errors.h"

namespace soupuv::io {
namespace {

using detail::fail_input;
using nlohmann::json;

// Extensions that change how geometry is stored: without them we would read
// garbage, so a file requiring them is refused rather than misread.
const char* const kUnsupportedGeometryExtensions[] = {"EXT_meshopt_compression", "KHR_meshopt_compression",
                                                      "EXT_mesh_gpu_instancing"};

void check_document(const json& doc) {
  if (!doc.is_object()) fail_input("glTF: top level is not a JSON object");
  const json* asset = detail::find_member(doc, "asset", "glTF document");
  if (!asset) fail_input("glTF: no 'asset' object");
  auto version = detail::get_opt_string(*asset, "version", "asset");
  if (!version) fail_input("glTF: asset.version missing");
  if (version->substr(0, 2) != "2.")
    throw Error(ErrorCode::unsupported, "glTF version '" + version->substr(0, 20) + "' is not 2.x");
  if (const json* required = detail::find_member(doc, "extensionsRequired", "glTF document")) {
    if (!required->is_array()) fail_input("glTF: extensionsRequired is not an array");
    for (const json& e : *required)
      for (const char* bad : kUnsupportedGeometryExtensions)
        if (e.is_string() && e.get<std::string>() == bad)
          throw Error(ErrorCode::unsupported, std::string("glTF requires ") + bad + ", which soupuv cannot read");
  }
}

// The writer rebuilds buffers; geometry payloads need not be kept twice.
void strip_data_uri_payloads(json& doc) {
  auto it = doc.find("buffers");
  if (it == doc.end() || !it->is_array()) return;
  for (json& b : *it)
    if (b.is_object() && b.contains("uri") && b["uri"].is_string() &&
        detail::is_data_uri(b["uri"].get_ref<const std::string&>()))
      b.erase("uri");
}

// Records source vertex v's kept attributes as soup vertex `at` (arrays grow
// zero-filled on demand; VertexAttributes::present says what is real).
void append_attributes(VertexAttributes& out, const detail::PrimitiveGeometry& prim, uint32_t v, size_t at) {
  out.present.resize(at + 1, 0);
  out.present[at] = prim.present;
  auto put = [&](auto& array, const auto& value) {
    if (array.size() <= at) array.resize(at + 1, {});
    array[at] = value;
  };
  if (!prim.normals.empty()) put(out.normals, prim.normals[v]);
  if (!prim.colors.empty()) put(out.colors, prim.colors[v]);
  if (out.texcoords.size() < prim.texcoords.size()) out.texcoords.resize(prim.texcoords.size());
  for (size_t n = 0; n < prim.texcoords.size(); ++n)
    if (!prim.texcoords[n].empty()) put(out.texcoords[n], prim.texcoords[n][v]);
  if (out.joints.size() < prim.joints.size()) {
    out.joints.resize(prim.joints.size());
    out.weights.resize(prim.joints.size());
  }
  for (size_t n = 0; n < prim.joints.size(); ++n)
    if (!prim.joints[n].empty()) {
      put(out.joints[n], prim.joints[n][v]);
      put(out.weights[n], prim.weights[n][v]);
    }
}

// Every non-empty attribute array as long as the soup's positions; no
// attribute at all: every array empty (present too).
void finish_attributes(VertexAttributes& a, size_t vertices) {
  if (a.empty()) {
    a.present.clear();
    return;
  }
  a.present.resize(vertices, 0);
  if (!a.normals.empty()) a.normals.resize(vertices, {});
  if (!a.colors.empty()) a.colors.resize(vertices, {});
  for (auto& uv : a.texcoords)
    if (!uv.empty()) uv.resize(vertices, {});
  while (!a.texcoords.empty() && a.texcoords.back().empty()) a.texcoords.pop_back();
  for (auto& uv : a.texcoords)
    if (uv.empty()) uv.resize(vertices, {});
  // Skin sets likewise: every set up to the last present one, full length.
  while (!a.joints.empty() && a.joints.back().empty()) {
    a.joints.pop_back();
    a.weights.pop_back();
  }
  for (auto& j : a.joints) j.resize(vertices, {});
  for (auto& w : a.weights) w.resize(vertices, {});
}

// Warnings repeated per primitive (a dropped attribute kind) said once.
void dedupe(std::vector<std::string>& warnings) {
  std::vector<std::string> out;
  for (auto& w : warnings)
    if (std::find(out.begin(), out.end(), w) == out.end()) out.push_back(std::move(w));
  warnings = std::move(out);
}

// Appends the triangles of one primitive placed by one instance, dropping
// zero-area ones (exactly zero cross product in world space).
void append_instance(Asset& asset, const detail::PrimitiveGeometry& prim, uint32_t instance_index,
                     int32_t primitive_index, const std::string& where) {
  const MeshInstance& inst = asset.instances[instance_index];
  Soup& soup = asset.soup;
  std::vector<uint32_t> remap(prim.positions.size(), UINT32_MAX);
  std::vector<Vec3> world(prim.positions.size());
  for (size_t v = 0; v < prim.positions.size(); ++v) {
    world[v] = detail::transform_point(inst.world, prim.positions[v]);
    if (!std::isfinite(world[v].x) || !std::isfinite(world[v].y) || !std::isfinite(world[v].z))
      fail_input(where + ": vertex overflows to a non-finite world position");
  }
  for (size_t t = 0; t < prim.triangles.size(); ++t) {
    const Tri& tri = prim.triangles[t];
    Vec3 a = world[tri[0]], b = world[tri[1]], c = world[tri[2]];
    if (norm2(cross(b - a, c - a)) == 0) {
      ++asset.dropped_degenerate;
      continue;
    }
    Tri out;
    for (int k = 0; k < 3; ++k) {
      uint32_t v = tri[k];
      if (remap[v] == UINT32_MAX) {
        remap[v] = uint32_t(soup.positions.size());
        append_attributes(asset.attributes, prim, v, soup.positions.size());
        soup.positions.push_back(world[v]);
        const Vec3& l = prim.positions[v];
        asset.local_positions.push_back({float(l.x), float(l.y), float(l.z)});
      }
      out[k] = remap[v];
    }
    soup.triangles.push_back(out);
    soup.origins.push_back({inst.node, inst.mesh, primitive_index, prim.material, prim.source_index[t]});
    asset.triangle_instance.push_back(instance_index);
  }
}

Asset load_gltf_document(json doc, std::span<const uint8_t> bin, bool has_bin, Format format,
                         const LoadOptions& options, uint64_t budget) {
  check_document(doc);
  Asset asset;
  asset.format = format;
  std::vector<std::string>& warnings = asset.soup.warnings;
  detail::BufferTable buffers(doc, bin, has_bin, options, budget);
  // Real scenes have thousands of nodes, not millions; a node DAG whose paths
  // multiply beyond this is an attack, refused before it costs time.
  constexpr uint64_t kMaxNodeVisits = 1'000'000;
  asset.instances = detail::flatten_scenes(doc, std::min(kMaxNodeVisits, options.max_triangles));

  // Each mesh is read once however often it is instanced.
  std::map<int32_t, std::vector<detail::PrimitiveGeometry>> meshes;
  uint64_t total = 0;
  for (const MeshInstance& inst : asset.instances) {
    auto [it, inserted] = meshes.try_emplace(inst.mesh);
    if (inserted) {
      const json& mesh = detail::element(doc, "meshes", uint64_t(inst.mesh), "node");
      const json* prims = detail::find_member(mesh, "primitives", "mesh " + std::to_string(inst.mesh));
      if (!prims || !prims->is_array()) fail_input("mesh " + std::to_string(inst.mesh) + " has no primitives array");
      for (size_t p = 0; p < prims->size(); ++p) {
        it->second.push_back(detail::read_primitive(doc, buffers, uint64_t(inst.mesh), p, options.max_bytes,
                                                    options.max_triangles, warnings));
        if (it->second.back().skipped) ++asset.skipped_primitives;
      }
    }
    for (const auto& prim : it->second) total += prim.triangles.size();
    if (total > options.max_triangles)
      throw Error(ErrorCode::limit_exceeded, "more than " + std::to_string(options.max_triangles) +
                                                 " triangles after instancing (limit)");
  }
  if (asset.skipped_primitives)
    warnings.push_back("skipped " + std::to_string(asset.skipped_primitives) + " points/lines primitive(s)");

  // Soup indices are 32-bit and vertices are not shared across instances.
  if (3 * total > UINT32_MAX)
    throw Error(ErrorCode::limit_exceeded, std::to_string(total) + " triangles exceed 32-bit vertex indexing");
  asset.soup.positions.reserve(size_t(3 * total));
  asset.local_positions.reserve(size_t(3 * total));
  asset.soup.triangles.reserve(size_t(total));
  asset.soup.origins.reserve(size_t(total));
  asset.triangle_instance.reserve(size_t(total));
  for (uint32_t i = 0; i < asset.instances.size(); ++i) {
    const auto& prims = meshes[asset.instances[i].mesh];
    for (size_t p = 0; p < prims.size(); ++p)
      append_instance(asset, prims[p], i, int32_t(p),
                      "node " + std::to_string(asset.instances[i].node) + " mesh " +
                          std::to_string(asset.instances[i].mesh) + " primitive " + std::to_string(p));
  }
  finish_attributes(asset.attributes, asset.soup.positions.size());
  detail::read_base_color_images(doc, buffers, asset, warnings);
  asset.skins = detail::read_source_skins(doc, buffers, options.max_bytes, warnings);
  dedupe(warnings);
  strip_data_uri_payloads(doc);
  asset.document = std::move(doc);
  return asset;
}

Asset load_drc(std::span<const uint8_t> bytes, const LoadOptions& options) {
  detail::DracoMesh mesh = detail::decode_draco(bytes, -1, options.max_triangles, "Draco file");
  Asset asset;
  asset.format = Format::drc;
  asset.document = {{"asset", {{"version", "2.0"}, {"generator", "soupuv (from raw Draco)"}}},
                    {"meshes", json::array({{{"primitives", json::array({{{"attributes", json::object()}}})}}})}};
  detail::PrimitiveGeometry prim;
  prim.positions = std::move(mesh.positions);
  prim.triangles = std::move(mesh.triangles);
  prim.source_index.resize(prim.triangles.size());
  for (size_t t = 0; t < prim.triangles.size(); ++t) prim.source_index[t] = uint32_t(t);
  detail::compact_and_check(prim.positions, prim.triangles, "Draco file");
  asset.instances.push_back(MeshInstance{});
  append_instance(asset, prim, 0, 0, "Draco file");
  return asset;
}

Asset load_sniffed(std::span<const uint8_t> bytes, const LoadOptions& options) {
  if (bytes.empty()) fail_input("empty input (0 bytes)");
  if (bytes.size() > options.max_bytes)
    throw Error(ErrorCode::limit_exceeded, "input of " + std::to_string(bytes.size()) +
                                               " bytes exceeds the limit of " + std::to_string(options.max_bytes));
  const uint64_t budget = options.max_bytes - bytes.size();
  if (detail::has_glb_magic(bytes)) {
    detail::GlbChunks chunks = detail::parse_glb(bytes);
    json doc = json::parse(chunks.json.begin(), chunks.json.end(), nullptr, false);
    if (doc.is_discarded()) fail_input("GLB: JSON chunk is not valid JSON");
    return load_gltf_document(std::move(doc), chunks.bin, chunks.has_bin, Format::glb, options, budget);
  }
  if (detail::has_draco_magic(bytes)) return load_drc(bytes, options);
  size_t start = 0;
  if (bytes.size() >= 3 && bytes[0] == 0xEF && bytes[1] == 0xBB && bytes[2] == 0xBF) start = 3;  // UTF-8 BOM
  while (start < bytes.size() && (bytes[start] == ' ' || bytes[start] == '\t' || bytes[start] == '\n' ||
                                  bytes[start] == '\r'))
    ++start;
  if (start < bytes.size() && bytes[start] == '{') {
    json doc = json::parse(bytes.begin() + start, bytes.end(), nullptr, false);
    if (doc.is_discarded()) fail_input("glTF: not valid JSON");
    return load_gltf_document(std::move(doc), {}, false, Format::gltf, options, budget);
  }
  fail_input("not a glTF, GLB or Draco file (unrecognized first bytes)");
}

void require_triangles(const Asset& asset) {
  if (!asset.soup.triangles.empty()) return;
  std::string why = "no triangles to map";
  if (asset.skipped_primitives) why += " (" + std::to_string(asset.skipped_primitives) + " points/lines primitives skipped)";
  if (asset.dropped_degenerate) why += " (" + std::to_string(asset.dropped_degenerate) + " zero-area triangles dropped)";
  if (asset.instances.empty() && asset.format != Format::drc) why += " (no scene node carries a mesh)";
  throw Error(ErrorCode::no_triangles, why);
}

}  // namespace

Asset load_memory(std::span<const uint8_t> bytes, const LoadOptions& options) {
  Asset asset;
  try {
    asset = load_sniffed(bytes, options);
  } catch (const json::exception& e) {
    // A safety net: the checked accessors should have caught malformed JSON shapes.
    throw Error(ErrorCode::invalid_input, std::string("glTF: malformed JSON structure: ") + e.what());
  } catch (const std::bad_alloc&) {
    throw Error(ErrorCode::limit_exceeded, "input needs more memory than available while loading");
  }
  if (asset.dropped_degenerate)
    asset.soup.warnings.push_back("dropped " + std::to_string(asset.dropped_degenerate) + " zero-area triangle(s)");
  require_triangles(asset);
  return asset;
}

Asset load_file(const std::string& path, const LoadOptions& options) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) fail_input("cannot open '" + path + "': not a readable file");
  uint64_t size = fs::file_size(path, ec);
  if (ec) fail_input("cannot read '" + path + "'");
  if (size > options.max_bytes)
    throw Error(ErrorCode::limit_exceeded, "'" + path + "' of " + std::to_string(size) +
                                               " bytes exceeds the limit of " + std::to_string(options.max_bytes));
  std::vector<uint8_t> bytes(static_cast<size_t>(size));
  std::ifstream in(path, std::ios::binary);
  if (size && !in.read(reinterpret_cast<char*>(bytes.data()), std::streamsize(size)))
    fail_input("cannot read '" + path + "'");
  LoadOptions resolved = options;
  // A local file's external buffers live beside it unless the caller says otherwise.
  if (resolved.allow_external_uris && resolved.base_dir.empty())
    resolved.base_dir = fs::path(path).parent_path().empty() ? "." : fs::path(path).parent_path().string();
  return load_memory(bytes, resolved);
}

}  // namespace soupuv::io
