#include "soupuv/server/auth.h"

#include <openssl/evp.h>

#include <algorithm>
#include <cctype>
#include <fstream>
#include <set>
#include <stdexcept>

namespace soupuv::server {
namespace {

std::string sha256_hex_prefix(std::string_view s, size_t hex_digits) {
  unsigned char md[EVP_MAX_MD_SIZE];
  unsigned int n = 0;
  if (EVP_Digest(s.data(), s.size(), md, &n, EVP_sha256(), nullptr) != 1)
    throw std::runtime_error("SHA-256 unavailable");
  static const char hex[] = "0123456789abcdef";
  std::string out;
  for (unsigned int i = 0; i < n && out.size() < hex_digits; ++i) {
    out += hex[md[i] >> 4];
    out += hex[md[i] & 15];
  }
  return out;
}

bool valid_tenant(std::string_view t) {
  return !t.empty() && t.size() <= 64 && std::all_of(t.begin(), t.end(), [](unsigned char c) {
    return std::isalnum(c) || c == '.' || c == '_' || c == '-';
  });
}

bool valid_token_chars(std::string_view t) {
  // RFC 6750 b64token characters: what a client can send after "Bearer ".
  return std::all_of(t.begin(), t.end(), [](unsigned char c) {
    return std::isalnum(c) || c == '-' || c == '.' || c == '_' || c == '~' || c == '+' || c == '/' || c == '=';
  });
}

}  // namespace

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
  std::set<std::string> seen;
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    const std::string where = "tokens file " + path + " line " + std::to_string(number) + ": ";
    std::vector<std::string> words;
    size_t i = 0;
    while (i < line.size()) {
      while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
      size_t start = i;
      while (i < line.size() && line[i] != ' ' && line[i] != '\t' && line[i] != '\r') ++i;
      if (i > start) words.push_back(line.substr(start, i - start));
    }
    if (words.empty() || words[0][0] == '#') continue;
    if (words.size() > 2) throw std::runtime_error(where + "expected TOKEN or TENANT TOKEN");
    Entry e;
    e.token = words.back();
    if (e.token.size() < kMinTokenBytes)
      throw std::runtime_error(where + "token shorter than " + std::to_string(kMinTokenBytes) + " bytes");
    if (!valid_token_chars(e.token))
      throw std::runtime_error(where + "token has characters outside [A-Za-z0-9-._~+/=]");
    if (!seen.insert(e.token).second) throw std::runtime_error(where + "token listed twice");
    if (words.size() == 2) {
      e.tenant = words[0];
      if (!valid_tenant(e.tenant))
        throw std::runtime_error(where + "tenant must be 1-64 characters of [A-Za-z0-9._-]");
    } else {
      e.tenant = "token-" + sha256_hex_prefix(e.token, 16);
    }
    set.entries_.push_back(std::move(e));
  }
  if (set.entries_.empty()) throw std::runtime_error("tokens file " + path + " has no tokens");
  return set;
}

std::optional<std::string> TokenSet::tenant_for(std::string_view token) const {
  if (token.empty()) return std::nullopt;
  const Entry* match = nullptr;
  for (const auto& e : entries_)  // no early exit
    if (constant_time_equal(token, e.token)) match = &e;
  if (!match) return std::nullopt;
  return match->tenant;
}

std::string_view TokenSet::bearer(std::string_view v) {
  constexpr std::string_view scheme = "bearer";
  if (v.size() <= scheme.size() + 1) return {};
  for (size_t i = 0; i < scheme.size(); ++i)
    if (std::tolower(static_cast<unsigned char>(v[i])) != scheme[i]) return {};
  size_t i = scheme.size();
  if (v[i] != ' ') return {};
  while (i < v.size() && v[i] == ' ') ++i;
  std::string_view token = v.substr(i);
  while (!token.empty() && (token.back() == ' ' || token.back() == '\t')) token.remove_suffix(1);
  if (token.empty() || !valid_token_chars(token)) return {};
  return token;
}

void TokenRegistry::set(TokenSet tokens) {
  auto next = std::make_shared<const TokenSet>(std::move(tokens));
  std::lock_guard lock(mu_);
  tokens_ = std::move(next);
}

std::shared_ptr<const TokenSet> TokenRegistry::get() const {
  std::lock_guard lock(mu_);
  return tokens_;
}

}  // namespace soupuv::server
