#include "soupuv/server/result_blobs.h"

#include "soupuv/server/blob_store.h"
#include "soupuv/server/log.h"

namespace soupuv::server {

std::string attempt_prefix(int attempt) { return "attempt-" + std::to_string(attempt) + "/"; }

std::string attempt_blob(int attempt, const std::string& name) { return attempt_prefix(attempt) + name; }

std::string result_blob(const Job& job, const std::string& name) {
  return job.result_attempt > 0 ? attempt_blob(job.result_attempt, name) : name;
}

void discard_attempt(BlobStore& blobs, const std::string& id, int attempt) noexcept {
  try {
    blobs.remove_attempt(id, attempt);
  } catch (const std::exception& e) {
    log::warn("blobs of a losing attempt not removed (the TTL sweep will)",
              {{"job", id}, {"attempt", attempt}, {"error", e.what()}});
  }
}

void discard_losing_attempts(BlobStore& blobs, const std::string& id, int winner) noexcept {
  // Attempts are numbered from 1 and a job's outcome is recorded once, so
  // the losers are exactly the attempts before the winner (at most
  // --max-attempts of them, most often none).
  for (int a = 1; a < winner; ++a) discard_attempt(blobs, id, a);
}

}  // namespace soupuv::server
