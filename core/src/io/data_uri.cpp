#include "io/data_uri.h"

#include <string>

#include "io/checked_json.h"
#include "soupuv/errors.h"

namespace soupuv::io::detail {
namespace {

int base64_value(char c) {
  if (c >= 'A' && c <= 'Z') return c - 'A';
  if (c >= 'a' && c <= 'z') return c - 'a' + 26;
  if (c >= '0' && c <= '9') return c - '0' + 52;
  if (c == '+' || c == '-') return 62;  // '-' and '_': the URL-safe alphabet
  if (c == '/' || c == '_') return 63;
  return -1;
}

}  // namespace

bool is_data_uri(std::string_view uri) { return uri.substr(0, 5) == "data:"; }

std::vector<uint8_t> decode_base64(std::string_view text, uint64_t max_bytes) {
  // Padding is optional in the wild; strip it and decode the remaining groups.
  size_t end = text.size();
  while (end > 0 && text[end - 1] == '=') --end;
  if (text.size() - end > 2) fail_input("data URI: too much base64 padding");
  size_t chars = end;
  if (chars % 4 == 1) fail_input("data URI: base64 length is impossible");
  uint64_t out_size = chars / 4 * 3 + (chars % 4 == 0 ? 0 : chars % 4 - 1);
  if (out_size > max_bytes)
    throw Error(ErrorCode::limit_exceeded, "data URI: payload of " + std::to_string(out_size) +
                                               " bytes exceeds the limit of " + std::to_string(max_bytes));
  std::vector<uint8_t> out;
  out.reserve(size_t(out_size));
  uint32_t acc = 0;
  int bits = 0;
  for (size_t i = 0; i < chars; ++i) {
    int v = base64_value(text[i]);
    if (v < 0) fail_input("data URI: invalid base64 character at offset " + std::to_string(i));
    acc = (acc << 6) | uint32_t(v);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out.push_back(uint8_t(acc >> bits));
      acc &= (1u << bits) - 1;
    }
  }
  return out;
}

std::vector<uint8_t> decode_data_uri(std::string_view uri, uint64_t max_bytes) {
  if (!is_data_uri(uri)) fail_input("not a data: URI");
  size_t comma = uri.find(',');
  if (comma == std::string_view::npos) fail_input("data URI: no ',' before the payload");
  std::string_view header = uri.substr(5, comma - 5);
  // glTF only writes base64 payloads; plain percent-encoded data would be text.
  if (header.size() < 7 || header.substr(header.size() - 7) != ";base64")
    throw Error(ErrorCode::unsupported, "data URI: only base64 payloads are supported");
  return decode_base64(uri.substr(comma + 1), max_bytes);
}

}  // namespace soupuv::io::detail
