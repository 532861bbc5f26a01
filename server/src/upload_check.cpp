#include "soupuv/server/upload_check.h"

#include <cstdint>
#include <cstring>
#include <fstream>

#include <nlohmann/json.hpp>

namespace soupuv::server {
namespace {

constexpr uint64_t kMaxJsonBytes = 64ull << 20;

UploadVerdict bad(const std::string& detail) { return {false, "invalid-model", detail}; }

uint32_t le32(const unsigned char* p) {
  return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
}

// The glTF JSON is attacker text parsed inside the server, so it is scanned,
// never built into a document: memory stays O(nesting depth + longest
// string) whatever the element count (a DOM of 64 MiB of "0," is over a GiB).
// Nesting is capped too. What is checked: the root is an object, "buffers"
// and "images" are arrays, and every item's "uri" is a data: URI.
constexpr size_t kMaxDepth = 512;

class UriScan final : public nlohmann::json_sax<nlohmann::json> {
 public:
  explicit UriScan(bool folder) : folder_(folder) {}
  UploadVerdict verdict;

  bool null() override { return value(false, nullptr); }
  bool boolean(bool) override { return value(false, nullptr); }
  bool number_integer(number_integer_t) override { return value(false, nullptr); }
  bool number_unsigned(number_unsigned_t) override { return value(false, nullptr); }
  bool number_float(number_float_t, const string_t&) override { return value(false, nullptr); }
  bool string(string_t& s) override { return value(false, &s); }
  bool binary(binary_t&) override { return value(false, nullptr); }
  bool start_object(std::size_t) override { return open('o'); }
  bool start_array(std::size_t) override { return open('a'); }
  bool end_object() override { return close(); }
  bool end_array() override { return close(); }
  bool key(string_t& k) override {
    if (stack_.size() == 1) top_key_ = k;
    if (in_item()) item_key_ = k;
    return true;
  }
  bool parse_error(std::size_t, const std::string&, const nlohmann::detail::exception&) override {
    if (verdict.ok) verdict = bad("the glTF JSON does not parse");
    return false;
  }

 private:
  bool list_key() const { return top_key_ == "buffers" || top_key_ == "images"; }
  bool in_item() const { return stack_ == "oao" && list_key(); }
  bool fail(UploadVerdict v) {
    verdict = std::move(v);
    return false;
  }
  // A scalar (or, with `container`, the opening of an object/array) at the current position.
  bool value(bool container, const std::string* text) {
    if (stack_.empty()) return fail(bad("glTF JSON must be an object"));
    if (stack_.size() == 1 && list_key()) return fail(bad(top_key_ + " must be an array"));
    if (in_item() && item_key_ == "uri" && (container || !text || text->rfind("data:", 0) != 0)) {
      if (!folder_)
        return fail({false, "external-uri",
                     "external URI in " + top_key_ +
                         " refused: send the files it names too (multipart 'files' parts or a .zip of the folder)"});
      if (container || !text || !plain_relative(*text))
        return fail({false, "external-uri",
                     "URI in " + top_key_ + " refused: only data: URIs and relative paths inside the upload's folder"});
    }
    return true;
  }
  bool open(char kind) {
    if (stack_.size() >= kMaxDepth) return fail(bad("the glTF JSON is nested too deeply"));
    if (stack_.empty() && kind != 'o') return fail(bad("glTF JSON must be an object"));
    if (!stack_.empty() && !(stack_.size() == 1 && list_key() && kind == 'a') && !value(true, nullptr)) return false;
    stack_ += kind;
    return true;
  }
  bool close() {
    if (in_item()) item_key_.clear();
    stack_.pop_back();
    return true;
  }

  // A relative reference that stays in the folder: no scheme, no absolute
  // path, no '..' (percent escapes of '.', '/' and '\\' refused outright).
  static bool plain_relative(const std::string& u) {
    if (u.empty() || u.find(':') != std::string::npos || u.front() == '/' || u.find('\\') != std::string::npos)
      return false;
    for (const char* esc : {"%2e", "%2E", "%2f", "%2F", "%5c", "%5C"})
      if (u.find(esc) != std::string::npos) return false;
    size_t start = 0;
    while (start <= u.size()) {
      size_t end = u.find('/', start);
      if (end == std::string::npos) end = u.size();
      if (u.compare(start, end - start, "..") == 0) return false;
      start = end + 1;
    }
    return true;
  }

  bool folder_;
  std::string stack_;  // 'o' / 'a' per open container
  std::string top_key_, item_key_;
};

template <typename Input>
UploadVerdict scan_gltf_json(Input&& input, bool folder) {
  UriScan scan(folder);
  nlohmann::json::sax_parse(std::forward<Input>(input), &scan);
  return scan.verdict;
}

}  // namespace

const char* file_name_for(ModelKind kind) {
  switch (kind) {
    case ModelKind::glb: return "input.glb";
    case ModelKind::gltf: return "input.gltf";
    case ModelKind::draco: return "input.drc";
  }
  return "input.bin";
}

UploadVerdict check_model_file(const std::filesystem::path& file, ModelKind kind, bool folder) {
  std::ifstream in(file, std::ios::binary);
  if (!in) return {false, "internal", "upload vanished"};
  in.seekg(0, std::ios::end);
  const uint64_t size = uint64_t(in.tellg());
  in.seekg(0);
  if (size == 0) return bad("the upload is empty");

  if (kind == ModelKind::draco) {
    char magic[5] = {};
    in.read(magic, 5);
    if (size < 5 || std::memcmp(magic, "DRACO", 5) != 0) return bad("not a Draco file (no DRACO magic)");
    return {};
  }
  if (kind == ModelKind::gltf) {
    if (size > kMaxJsonBytes) return {false, "too-large", "glTF JSON larger than 64 MiB"};
    return scan_gltf_json(in, folder);  // streamed from the file
  }
  unsigned char header[20] = {};
  in.read(reinterpret_cast<char*>(header), 20);
  if (size < 20) return bad("too short for a GLB (needs a 12-byte header and a chunk header)");
  if (std::memcmp(header, "glTF", 4) != 0) return bad("not a GLB: the magic is not 'glTF'");
  if (le32(header + 4) != 2) return bad("unsupported GLB version " + std::to_string(le32(header + 4)));
  if (le32(header + 8) != size)
    return bad("GLB header length " + std::to_string(le32(header + 8)) + " differs from the " +
               std::to_string(size) + " bytes received");
  const uint64_t json_len = le32(header + 12);
  if (le32(header + 16) != 0x4E4F534Au) return bad("the first GLB chunk is not JSON");
  if (json_len > size - 20 || json_len > kMaxJsonBytes) return bad("GLB JSON chunk runs past the end of the file");
  std::string text(json_len, '\0');
  in.read(text.data(), std::streamsize(json_len));
  return scan_gltf_json(text, folder);
}

}  // namespace soupuv::server
