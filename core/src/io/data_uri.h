// data: URIs and base64, decoded by our own code with a size cap.
//
// Input : a URI string starting with "data:" and the largest payload accepted.
// Output: the decoded bytes, or Error{invalid_input} (not base64, bad
//         characters or padding) / Error{limit_exceeded} (payload too large).
#pragma once

#include <cstdint>
#include <string_view>
#include <vector>

namespace soupuv::io::detail {

bool is_data_uri(std::string_view uri);
std::vector<uint8_t> decode_data_uri(std::string_view uri, uint64_t max_bytes);
std::vector<uint8_t> decode_base64(std::string_view text, uint64_t max_bytes);

}  // namespace soupuv::io::detail
