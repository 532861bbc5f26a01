#include "soupuv/server/problem.h"

namespace soupuv::server {

const char* status_title(int status) {
  switch (status) {
    case 400: return "Bad Request";
    case 401: return "Unauthorized";
    case 403: return "Forbidden";
    case 404: return "Not Found";
    case 405: return "Method Not Allowed";
    case 409: return "Conflict";
    case 411: return "Length Required";
    case 413: return "Content Too Large";
    case 414: return "URI Too Long";
    case 415: return "Unsupported Media Type";
    case 422: return "Unprocessable Content";
    case 429: return "Too Many Requests";
    case 500: return "Internal Server Error";
    case 501: return "Not Implemented";
    case 503: return "Service Unavailable";
    case 504: return "Gateway Timeout";
    default: return "Error";
  }
}

void set_problem(httplib::Response& res, int status, const std::string& slug, const std::string& detail,
                 const nlohmann::json& extra) {
  nlohmann::json p = {{"type", "https://soupuv.dev/problems/" + slug},
                      {"title", status_title(status)},
                      {"status", status},
                      {"detail", detail}};
  if (extra.is_object())
    for (auto it = extra.begin(); it != extra.end(); ++it) p[it.key()] = it.value();
  res.status = status;
  res.set_content(p.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace),
                  "application/problem+json");
}

}  // namespace soupuv::server
