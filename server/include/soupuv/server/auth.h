// Bearer-token authentication. Tokens file: one token per line, '#' comments
// and blank lines ignored. Comparison is constant-time in the token's content
// (every configured token is compared in full), so timing does not leak prefixes.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace soupuv::server {

class TokenSet {
 public:
  TokenSet() = default;
  static TokenSet load(const std::string& path);  // throws std::runtime_error
  bool enabled() const { return !tokens_.empty(); }
  bool accepts(std::string_view token) const;
  // Parses "Authorization: Bearer <token>"; empty when absent or malformed.
  static std::string_view bearer(std::string_view header_value);

 private:
  std::vector<std::string> tokens_;
};

bool constant_time_equal(std::string_view a, std::string_view b);

}  // namespace soupuv::server
