#include "soupuv/server/http_guards.h"

#include <algorithm>
#include <cctype>

namespace soupuv::server {

std::string media_type(const std::string& v) {
  std::string m = v.substr(0, v.find(';'));
  while (!m.empty() && std::isspace(static_cast<unsigned char>(m.back()))) m.pop_back();
  size_t start = 0;
  while (start < m.size() && std::isspace(static_cast<unsigned char>(m[start]))) ++start;
  m = m.substr(start);
  std::transform(m.begin(), m.end(), m.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return m;
}

bool is_accepted_upload_type(const std::string& m) {
  return m == "model/gltf-binary" || m == "model/gltf+json" || m == "application/octet-stream" ||
         m == "multipart/form-data" || m == "application/zip";
}

std::optional<Rejection> check_request_headers(const httplib::Request& req, int64_t max_upload_bytes) {
  if (req.path.size() > kMaxPathBytes) return Rejection{414, "uri-too-long", "request path is too long"};
  if (req.has_header("Transfer-Encoding"))
    return Rejection{411, "length-required", "Transfer-Encoding is not accepted; send Content-Length"};
  if (req.has_header("Content-Encoding"))
    return Rejection{415, "unsupported-encoding", "Content-Encoding is not accepted; send the file as is"};

  // POST /v1/jobs/{id}:cancel is an action without a body: no Content-Length needed.
  const bool is_action = req.method == "POST" && req.path.size() > 7 &&
                         req.path.compare(req.path.size() - 7, 7, ":cancel") == 0;
  const bool has_body_method = (req.method == "POST" && !is_action) || req.method == "PUT" || req.method == "PATCH";
  const size_t lengths = req.get_header_value_count("Content-Length");
  if (lengths > 1) return Rejection{411, "length-required", "duplicate Content-Length"};
  int64_t length = 0;
  if (lengths == 1) {
    const std::string v = req.get_header_value("Content-Length");
    if (v.empty() || v.size() > 18 || !std::all_of(v.begin(), v.end(), [](unsigned char c) { return std::isdigit(c); }))
      return Rejection{411, "length-required", "Content-Length is not a decimal number"};
    length = std::stoll(v);
  } else if (has_body_method) {
    return Rejection{411, "length-required", "Content-Length is required"};
  }
  if (length > max_upload_bytes)
    return Rejection{413, "too-large",
                     "body of " + std::to_string(length) + " bytes exceeds the limit of " +
                         std::to_string(max_upload_bytes) + " bytes"};
  const bool is_submit = req.method == "POST" && req.path == "/v1/jobs";
  if ((has_body_method || length > 0) && !is_submit)
    return Rejection{405, "method-not-allowed", "this resource takes no request body"};
  if (is_submit) {
    const std::string m = media_type(req.get_header_value("Content-Type"));
    if (!is_accepted_upload_type(m))
      return Rejection{415, "unsupported-media-type",
                       "Content-Type must be model/gltf-binary, model/gltf+json, application/octet-stream "
                       "(Draco), application/zip (a model's folder) or multipart/form-data"};
  }
  return std::nullopt;
}

}  // namespace soupuv::server
