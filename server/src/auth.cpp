#include "soupuv/server/auth.h"

#include <fstream>
#include <stdexcept>

namespace soupuv::server {

bool constant_time_equal(std::string_view a, std::string_view b) {
  // Length is not secret (tokens are of a fixed, documented shape); content is.
  size_t n = std::max(a.size(), b.size());
  unsigned char diff = a.size() == b.size() ? 0 : 1;
  for (size_t i = 0; i < n; ++i) {
    unsigned char x = i < a.size() ? static_cast<unsigned char>(a[i]) : 0;
    unsigned char y = i < b.size() ? static_cast<unsigned char>(b[i]) : 0;
    diff |= static_cast<unsigned char>(x ^ y);
  }
  return diff == 0;
}

TokenSet TokenSet::load(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read tokens file " + path);
  TokenSet set;
  std::string line;
  while (std::getline(in, line)) {
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ' || line.back() == '\t')) line.pop_back();
    size_t start = line.find_first_not_of(" \t");
    if (start == std::string::npos || line[start] == '#') continue;
    set.tokens_.push_back(line.substr(start));
  }
  if (set.tokens_.empty()) throw std::runtime_error("tokens file " + path + " has no tokens");
  return set;
}

bool TokenSet::accepts(std::string_view token) const {
  if (token.empty()) return false;
  bool ok = false;
  for (const auto& t : tokens_) ok |= constant_time_equal(token, t);  // no early exit
  return ok;
}

std::string_view TokenSet::bearer(std::string_view v) {
  constexpr std::string_view prefix = "Bearer ";
  if (v.size() <= prefix.size() || v.substr(0, prefix.size()) != prefix) return {};
  return v.substr(prefix.size());
}

}  // namespace soupuv::server
