// RFC 9457 problem details: every error the server answers is
// application/problem+json {type, title, status, detail, instance?, ...}.
#pragma once

#include <string>
#include <vector>

#include <httplib.h>
#include <nlohmann/json.hpp>

namespace soupuv::server {

// `slug` names a problem type; `type` becomes "/problems/<slug>", a reference
// relative to the server, which serves that page (GET /problems/<slug>: what
// the problem means and what a client should do). Every slug is in
// problem_types(); an unknown one is logged and answered as "about:blank".
void set_problem(httplib::Response& res, int status, const std::string& slug, const std::string& detail,
                 const nlohmann::json& extra = nlohmann::json::object());
const char* status_title(int status);

struct ProblemType {
  const char* slug;
  const char* title;
  const char* meaning;  // one or two sentences for people: cause and what to do
};
const std::vector<ProblemType>& problem_types();
const ProblemType* find_problem_type(const std::string& slug);

}  // namespace soupuv::server
