#include "soupuv/server/list_cursor.h"

#include <algorithm>
#include <cctype>
#include <cstdint>

namespace soupuv::server {

std::string encode_list_cursor(const std::string& store_cursor) {
  if (store_cursor.empty()) return "";
  static const char a[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789-_";
  const std::string in = "c1:" + store_cursor;
  std::string out;
  for (size_t i = 0; i < in.size(); i += 3) {
    uint32_t v = uint32_t(uint8_t(in[i])) << 16;
    if (i + 1 < in.size()) v |= uint32_t(uint8_t(in[i + 1])) << 8;
    if (i + 2 < in.size()) v |= uint32_t(uint8_t(in[i + 2]));
    out += a[(v >> 18) & 63];
    out += a[(v >> 12) & 63];
    if (i + 1 < in.size()) out += a[(v >> 6) & 63];
    if (i + 2 < in.size()) out += a[v & 63];
  }
  return out;
}

std::optional<std::string> decode_list_cursor(const std::string& c) {
  if (c.empty()) return std::string();
  if (c.size() > 64) return std::nullopt;
  std::string bytes;
  uint32_t acc = 0;
  int bits = 0;
  for (char ch : c) {
    int v = ch >= 'A' && ch <= 'Z' ? ch - 'A' : ch >= 'a' && ch <= 'z' ? ch - 'a' + 26
          : ch >= '0' && ch <= '9' ? ch - '0' + 52 : ch == '-' ? 62 : ch == '_' ? 63 : -1;
    if (v < 0) return std::nullopt;
    acc = (acc << 6) | uint32_t(v);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      bytes += char((acc >> bits) & 0xff);
    }
  }
  if (bytes.rfind("c1:", 0) != 0) return std::nullopt;
  std::string seq = bytes.substr(3);
  if (seq.empty() || seq.size() > 19 || !std::all_of(seq.begin(), seq.end(), ::isdigit)) return std::nullopt;
  return seq;
}

}  // namespace soupuv::server
