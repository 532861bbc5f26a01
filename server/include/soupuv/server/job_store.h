// Where job metadata lives. The embedded default is SqliteJobStore (one file,
// WAL mode); a store shared by several machines implements the same interface.
// Every method is safe to call from many threads.
#pragma once

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "soupuv/server/job.h"

namespace soupuv::server {

struct JobPage {
  std::vector<Job> jobs;
  std::string next_cursor;  // empty when this is the last page
};

class JobStore {
 public:
  virtual ~JobStore() = default;

  // Inserts a new job. If job.idempotency_key is set and already used by the
  // same tenant, nothing is inserted and that tenant's job is returned instead.
  virtual std::optional<Job> create_or_get_by_key(const Job& job) = 0;
  virtual std::optional<Job> get(const std::string& id) = 0;
  // Newest first; cursor is an opaque value from a previous page. `tenant`:
  // only that tenant's jobs; nullopt: every job (startup, the sweeper).
  virtual JobPage list(std::optional<JobState> state, int limit, const std::string& cursor,
                       const std::optional<std::string>& tenant) = 0;

  virtual void mark_running(const std::string& id, double at) = 0;  // attempts += 1
  // Back to queued for another attempt (attempts kept, progress cleared).
  virtual void requeue(const std::string& id) = 0;
  virtual void update_progress(const std::string& id, const std::string& stage, double fraction,
                               const nlohmann::json& stage_seconds) = 0;
  // The job's outcome. `result_attempt`: the attempt whose blobs hold
  // `outputs` (result_blobs.h), recorded in the same write; 0 with no outputs.
  virtual void finish(const std::string& id, JobState state, const std::optional<JobError>& error,
                      const std::vector<std::string>& outputs, int result_attempt, double at) = 0;
  virtual void request_cancel(const std::string& id) = 0;
  virtual void remove(const std::string& id) = 0;

  // Restart recovery: queued and running jobs, oldest first.
  virtual std::vector<Job> unfinished() = 0;
  // Finished jobs whose finished_at is before `before`.
  virtual std::vector<std::string> finished_before(double before) = 0;
  virtual std::map<std::string, int64_t> count_by_state() = 0;
};

// Opens (creating if needed) the SQLite database at `path`. Throws std::runtime_error.
std::unique_ptr<JobStore> open_sqlite_job_store(const std::string& path);

// Wraps a durable store with an in-memory copy of every job: get() and
// count_by_state() are answered from memory (status polls never wait for a
// database write); writes go to `durable` first (snapshot_job_store.cpp).
std::unique_ptr<JobStore> with_memory_snapshot(std::unique_ptr<JobStore> durable);

}  // namespace soupuv::server
