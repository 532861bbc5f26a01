#include "soupuv/server/job.h"

#include <chrono>
#include <cmath>
#include <ctime>

namespace soupuv::server {

const char* to_string(JobState s) {
  switch (s) {
    case JobState::queued: return "queued";
    case JobState::running: return "running";
    case JobState::succeeded: return "succeeded";
    case JobState::failed: return "failed";
    case JobState::canceled: return "canceled";
  }
  return "failed";
}

std::optional<JobState> parse_job_state(const std::string& s) {
  for (JobState st : {JobState::queued, JobState::running, JobState::succeeded, JobState::failed,
                      JobState::canceled})
    if (s == to_string(st)) return st;
  return std::nullopt;
}

double now_seconds() {
  using namespace std::chrono;
  return duration<double>(system_clock::now().time_since_epoch()).count();
}

std::string iso8601(double t) {
  std::time_t secs = std::time_t(std::floor(t));
  int millis = int((t - std::floor(t)) * 1000);
  std::tm tm{};
  gmtime_r(&secs, &tm);
  char buf[64];
  std::snprintf(buf, sizeof buf, "%04d-%02d-%02dT%02d:%02d:%02d.%03dZ", tm.tm_year + 1900,
                tm.tm_mon + 1, tm.tm_mday, tm.tm_hour, tm.tm_min, tm.tm_sec, millis);
  return buf;
}

nlohmann::json to_json(const Job& job) {
  nlohmann::json j;
  j["id"] = job.id;
  j["state"] = to_string(job.state);
  j["created_at"] = iso8601(job.created_at);
  j["started_at"] = job.started_at > 0 ? nlohmann::json(iso8601(job.started_at)) : nlohmann::json();
  j["finished_at"] = job.finished_at > 0 ? nlohmann::json(iso8601(job.finished_at)) : nlohmann::json();
  if (job.state == JobState::running) {
    j["stage"] = job.stage;
    j["fraction"] = job.fraction;
  }
  j["stage_seconds"] = job.stage_seconds;
  j["params"] = job.params;
  // The caller's metadata, also at the top level where an integrator looks for it.
  if (job.params.contains("metadata")) j["metadata"] = job.params["metadata"];
  j["input"] = {{"content_type", job.content_type}, {"bytes", job.input_bytes}};
  j["attempts"] = job.attempts;
  if (job.error)
    j["error"] = {{"code", job.error->code}, {"status", job.error->http_status},
                  {"detail", job.error->detail}};
  nlohmann::json links = {{"self", "/v1/jobs/" + job.id}};
  for (const auto& f : job.outputs) {
    if (f == "result.glb") links["result"] = "/v1/jobs/" + job.id + "/result";
    else if (f == "diagnostics.json") links["diagnostics"] = "/v1/jobs/" + job.id + "/diagnostics";
    else links[f] = "/v1/jobs/" + job.id + "/" + f;
  }
  j["links"] = links;
  return j;
}

}  // namespace soupuv::server
