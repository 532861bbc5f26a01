// A mapping job as the API and the store see it. The JSON form (to_json) is the
// contract in proto/job.schema.json: it always has "id" and "state".
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace soupuv::server {

enum class JobState { queued, running, succeeded, failed, canceled };

const char* to_string(JobState s);
std::optional<JobState> parse_job_state(const std::string& s);
inline bool is_finished(JobState s) {
  return s == JobState::succeeded || s == JobState::failed || s == JobState::canceled;
}

struct JobError {
  std::string code;    // invalid_input, no_triangles, timeout, crashed, ... (stable)
  int http_status = 0; // what a synchronous answer would have been (400, 422, 500)
  std::string detail;  // one line for people
};

struct Job {
  std::string id;
  JobState state = JobState::queued;
  double created_at = 0, started_at = 0, finished_at = 0;  // unix seconds; 0 = not yet
  std::string stage;       // current stage while running
  double fraction = 0;     // of the current stage
  nlohmann::json stage_seconds = nlohmann::json::object();  // finished stages
  std::optional<JobError> error;
  nlohmann::json params = nlohmann::json::object();  // validated, canonical
  std::string input_file;     // file name inside the job directory (input.glb, ...)
  std::string content_type;   // of the uploaded model
  int64_t input_bytes = 0;
  std::string tenant;          // who may see it (auth.h); "" when the server runs without tokens
  std::string idempotency_key;  // the client's key; unique per tenant
  std::string request_hash;   // body + params, for Idempotency-Key reuse checks
  int attempts = 0;           // worker starts (restart recovery re-runs)
  bool cancel_requested = false;
  std::vector<std::string> outputs;  // result files present: result.glb, diagnostics.json, ...
  // The attempt whose blobs are the result (result_blobs.h), recorded with
  // the outcome; 0: none, or a job finished before results were per attempt.
  int result_attempt = 0;
};

nlohmann::json to_json(const Job& job);
std::string iso8601(double unix_seconds);
double now_seconds();

}  // namespace soupuv::server
