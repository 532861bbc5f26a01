// The list cursor of GET /v1/jobs is opaque to clients ("next_cursor" out,
// "cursor" back in): the store's position (its decimal sequence number),
// base64url-encoded behind a version tag, so clients cannot build or depend
// on it and a later store can change what it holds.
#pragma once

#include <optional>
#include <string>

namespace soupuv::server {

// "" for "" (no next page).
std::string encode_list_cursor(const std::string& store_cursor);
// The store cursor inside an API cursor ("" for ""); nullopt if it is not one of ours.
std::optional<std::string> decode_list_cursor(const std::string& api_cursor);

}  // namespace soupuv::server
