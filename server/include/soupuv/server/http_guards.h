// Request checks done on headers alone, before any body byte is read (Debian's
// cpp-httplib 0.11.4 would otherwise read, decompress or buffer first):
//   Transfer-Encoding (chunked bodies have no length to budget) -> 411
//   any Content-Encoding (decompression bombs)                  -> 415
//   body method without, or with a duplicate/invalid, Content-Length -> 411
//   Content-Length above the upload limit                      -> 413
//   path longer than kMaxPathBytes                              -> 414
//   body to anything but POST /v1/jobs                          -> 405
//   POST /v1/jobs with a content type we do not take            -> 415
// The same checks answer `Expect: 100-continue` with the final status, so a
// client never sends a body that would be refused.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include <httplib.h>

namespace soupuv::server {

constexpr size_t kMaxPathBytes = 1024;

struct Rejection {
  int status;
  std::string slug;
  std::string detail;
};

std::optional<Rejection> check_request_headers(const httplib::Request& req, int64_t max_upload_bytes);

// The media type without parameters, lowercased ("multipart/form-data").
std::string media_type(const std::string& content_type_header);
bool is_accepted_upload_type(const std::string& media);

}  // namespace soupuv::server
