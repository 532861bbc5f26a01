// RFC 9457 problem details: every error the server answers is
// application/problem+json {type, title, status, detail, instance?, ...}.
#pragma once

#include <string>

#include <httplib.h>
#include <nlohmann/json.hpp>

namespace soupuv::server {

// `type` is a short slug; it becomes "https://soupuv.dev/problems/<slug>" —
// an identifier, not a page we promise to host.
void set_problem(httplib::Response& res, int status, const std::string& slug, const std::string& detail,
                 const nlohmann::json& extra = nlohmann::json::object());
const char* status_title(int status);

}  // namespace soupuv::server
