// Bearer-token authentication and tenants.
//
// Tokens file: one `TOKEN` or `TENANT TOKEN` a line, '#' comments and blank
// lines ignored. A token alone is its own tenant, named "token-" + the first
// 16 hex digits of its SHA-256 (the token itself never reaches the job store
// or the logs). Tenant names are 1-64 of [A-Za-z0-9._-]. Tokens must be at
// least 32 bytes (guessing must be hopeless) and unique; a file breaking a
// rule is refused whole, with the line number.
//
// Comparison is constant-time in the token's content and every configured
// token is compared in full, so timing does not leak prefixes or which token
// matched.
#pragma once

#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace soupuv::server {

constexpr size_t kMinTokenBytes = 32;

class TokenSet {
 public:
  TokenSet() = default;
  static TokenSet load(const std::string& path);  // throws std::runtime_error
  bool enabled() const { return !entries_.empty(); }
  // The tenant of `token`, or nullopt when no configured token matches.
  std::optional<std::string> tenant_for(std::string_view token) const;
  bool accepts(std::string_view token) const { return tenant_for(token).has_value(); }
  size_t size() const { return entries_.size(); }
  // Parses "Authorization: Bearer <token>" (scheme case-insensitive, RFC
  // 9110 §11.1); empty when absent or malformed.
  static std::string_view bearer(std::string_view header_value);

 private:
  struct Entry {
    std::string tenant, token;
  };
  std::vector<Entry> entries_;
};

// The tokens in force, swapped whole on reload (SIGHUP) while requests read them.
class TokenRegistry {
 public:
  void set(TokenSet tokens);
  std::shared_ptr<const TokenSet> get() const;
  bool enabled() const { return get()->enabled(); }

 private:
  mutable std::mutex mu_;
  std::shared_ptr<const TokenSet> tokens_ = std::make_shared<const TokenSet>();
};

bool constant_time_equal(std::string_view a, std::string_view b);

}  // namespace soupuv::server
