#include "io/buffer_table.h"

#include <algorithm>
#include <filesystem>
#include <fstream>

#include "io/checked_json.h"
#include "io/data_uri.h"
#include "soupuv/errors.h"

namespace soupuv::io::detail {
namespace fs = std::filesystem;

namespace {

int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

std::string percent_decode(const std::string& uri) {
  std::string out;
  for (size_t i = 0; i < uri.size(); ++i) {
    if (uri[i] == '%') {
      int hi = i + 2 < uri.size() ? hex_value(uri[i + 1]) : -1;
      int lo = i + 2 < uri.size() ? hex_value(uri[i + 2]) : -1;
      if (hi < 0 || lo < 0) fail_input("external URI '" + uri + "' has a bad percent escape");
      out.push_back(char(hi * 16 + lo));
      i += 2;
    } else {
      out.push_back(uri[i]);
    }
  }
  return out;
}

}  // namespace

std::string resolve_external_path(const std::string& uri, const std::string& base_dir) {
  if (uri.find(':') != std::string::npos)
    throw Error(ErrorCode::unsupported, "external URI '" + uri + "' has a scheme; only relative paths are allowed");
  std::string path = percent_decode(uri);
  if (path.empty() || path.find('\0') != std::string::npos || path.find('\\') != std::string::npos)
    fail_input("external URI '" + uri + "' is not a plain relative path");
  fs::path rel(path);
  if (rel.is_absolute() || rel.has_root_name() || rel.has_root_directory())
    throw Error(ErrorCode::unsupported, "external URI '" + uri + "' is absolute; it must stay inside " + base_dir);
  for (const auto& part : rel)
    if (part == "..")
      throw Error(ErrorCode::unsupported, "external URI '" + uri + "' climbs out with '..'; it must stay inside " + base_dir);
  // Symlinks could still lead out: compare the real paths.
  std::error_code ec;
  fs::path base = fs::weakly_canonical(fs::path(base_dir), ec);
  if (ec) fail_input("base directory '" + base_dir + "' cannot be resolved");
  fs::path full = fs::weakly_canonical(base / rel, ec);
  if (ec) fail_input("external URI '" + uri + "' cannot be resolved");
  auto [b, f] = std::mismatch(base.begin(), base.end(), full.begin(), full.end());
  if (b != base.end())
    throw Error(ErrorCode::unsupported, "external URI '" + uri + "' leads outside " + base_dir);
  return full.string();
}

BufferTable::BufferTable(const nlohmann::json& doc, std::span<const uint8_t> glb_bin, bool has_bin,
                         const LoadOptions& options, uint64_t budget)
    : doc_(doc), glb_bin_(glb_bin), has_bin_(has_bin), options_(options), budget_(budget) {
  size_t n = array_size(doc, "buffers");
  owned_.resize(n);
  resolved_.resize(n);
  is_resolved_.assign(n, false);
}

std::vector<uint8_t> BufferTable::read_external(const std::string& uri, const std::string& where) {
  if (!options_.allow_external_uris || options_.base_dir.empty())
    throw Error(ErrorCode::unsupported, where + ": external file '" + uri.substr(0, 200) +
                                            "' refused: reading files beside the model is off (CLI: "
                                            "--no-external-files; in memory: no base directory)");
  std::string path = resolve_external_path(uri, options_.base_dir);
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) fail_input(where + ": external file '" + uri + "' not found");
  uint64_t size = fs::file_size(path, ec);
  if (ec) fail_input(where + ": external file '" + uri + "' cannot be read");
  if (size > budget_)
    throw Error(ErrorCode::limit_exceeded, where + ": external file '" + uri + "' exceeds the byte limit");
  std::vector<uint8_t> data(static_cast<size_t>(size));
  std::ifstream in(path, std::ios::binary);
  if (!in.read(reinterpret_cast<char*>(data.data()), std::streamsize(size)))
    fail_input(where + ": external file '" + uri + "' cannot be read");
  return data;
}

std::span<const uint8_t> BufferTable::buffer(uint64_t index, const std::string& where) {
  const nlohmann::json& b = element(doc_, "buffers", index, where);
  if (is_resolved_[index]) return resolved_[index];
  std::string name = "buffer " + std::to_string(index);
  uint64_t byte_length = get_uint(b, "byteLength", name);
  auto uri = get_opt_string(b, "uri", name);
  std::span<const uint8_t> data;
  if (!uri) {
    // Without a uri, buffer 0 of a GLB is its BIN chunk.
    if (index != 0 || !has_bin_) fail_input(name + " has no uri and there is no GLB BIN chunk for it");
    data = glb_bin_;
  } else {
    auto bytes = std::make_unique<std::vector<uint8_t>>(
        is_data_uri(*uri) ? decode_data_uri(*uri, budget_) : read_external(*uri, name));
    budget_ -= std::min<uint64_t>(budget_, bytes->size());
    data = *bytes;
    owned_[index] = std::move(bytes);
  }
  if (data.size() < byte_length)
    fail_input(name + ": byteLength " + std::to_string(byte_length) + " but only " +
               std::to_string(data.size()) + " bytes present");
  resolved_[index] = data.first(size_t(byte_length));
  is_resolved_[index] = true;
  return resolved_[index];
}

std::vector<uint8_t> BufferTable::read_uri(const std::string& uri, const std::string& where) {
  std::vector<uint8_t> bytes = is_data_uri(uri) ? decode_data_uri(uri, budget_) : read_external(uri, where);
  budget_ -= std::min<uint64_t>(budget_, bytes.size());
  return bytes;
}

ViewBytes BufferTable::view(uint64_t index, const std::string& where) {
  const nlohmann::json& v = element(doc_, "bufferViews", index, where);
  std::string name = "bufferView " + std::to_string(index);
  uint64_t buffer_index = get_uint(v, "buffer", name);
  uint64_t offset = get_opt_uint(v, "byteOffset", name).value_or(0);
  uint64_t length = get_uint(v, "byteLength", name);
  uint64_t stride = get_opt_uint(v, "byteStride", name).value_or(0);
  if (stride != 0 && (stride < 4 || stride > 252 || stride % 4 != 0))
    fail_input(name + ": byteStride " + std::to_string(stride) + " is not a multiple of 4 in [4, 252]");
  auto buf = buffer(buffer_index, name);
  if (checked_add(offset, length, name) > buf.size())
    fail_input(name + ": byteOffset " + std::to_string(offset) + " + byteLength " + std::to_string(length) +
               " exceeds buffer " + std::to_string(buffer_index) + " of " + std::to_string(buf.size()) + " bytes");
  return {buf.subspan(size_t(offset), size_t(length)), stride};
}

}  // namespace soupuv::io::detail
