// Where a job's result files live in the blob store, and which of them are
// the job's result.
//
// Two attempts of one job can both store results: a worker that lost its
// lease after its last lease check (its node paused, cut off) and the re-run
// that took the job over. If both wrote `result.glb`, the later write would
// win whatever the job row says. So every attempt writes its own blobs,
// "attempt-<n>/<name>", and the job's outcome names the attempt whose blobs
// are its result (Job::result_attempt), set in the same write as the state:
// the lease-conditioned JobQueue::complete() on PostgreSQL, JobStore::finish()
// in the embedded store. Readers go through result_blob(); a late loser only
// adds blobs nobody reads, which it deletes once its outcome is refused (or
// the winner deletes them, or the TTL sweep removes them with the job).
#pragma once

#include <optional>
#include <string>

#include "soupuv/server/job.h"

namespace soupuv::server {

class BlobStore;

// The blob that attempt `attempt` (1, 2, ...) stores output `name` under.
std::string attempt_blob(int attempt, const std::string& name);
// "attempt-<n>/": the prefix of every blob of that attempt.
std::string attempt_prefix(int attempt);
// The blob holding `job`'s output `name`: its result attempt's; jobs finished
// before results were stored per attempt (result_attempt 0) have theirs
// under the plain name.
std::string result_blob(const Job& job, const std::string& name);

// Best effort (errors are logged; the TTL sweep removes what stays):
// the blobs of attempts 1 .. winner-1 of job `id`, stored by attempts that
// lost the job, once `winner`'s outcome is recorded.
void discard_losing_attempts(BlobStore& blobs, const std::string& id, int winner) noexcept;
// The blobs of one attempt whose outcome was refused.
void discard_attempt(BlobStore& blobs, const std::string& id, int attempt) noexcept;

}  // namespace soupuv::server
