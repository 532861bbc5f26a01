// JobStore and JobQueue on PostgreSQL (--database-url): the one store every
// node of a service shares. Tables: pg_schema.cpp. Reads are not cached in
// the process (no memory snapshot as with SQLite): another node may have
// changed any row, and a primary-key read on a pooled connection costs a
// fraction of a millisecond, so status polls read through.
#pragma once

#include <memory>

#include "soupuv/server/job_queue.h"
#include "soupuv/server/job_store.h"
#include "soupuv/server/pg_connection.h"

namespace soupuv::server {

class PgJobStore final : public JobStore, public JobQueue {
 public:
  // `advisory`: connections for heartbeats and progress, opened with
  // kAdvisoryWrites (nullptr: `pool`).
  explicit PgJobStore(PgPool& pool, PgPool* advisory = nullptr) : pool_(pool), advisory_(advisory ? *advisory : pool) {}

  // JobStore
  std::optional<Job> create_or_get_by_key(const Job& job) override;
  std::optional<Job> get(const std::string& id) override;
  JobPage list(std::optional<JobState> state, int limit, const std::string& cursor,
               const std::optional<std::string>& tenant) override;
  void mark_running(const std::string& id, double at) override;
  void requeue(const std::string& id) override;
  void update_progress(const std::string& id, const std::string& stage, double fraction,
                       const nlohmann::json& stage_seconds) override;
  void finish(const std::string& id, JobState state, const std::optional<JobError>& error,
              const std::vector<std::string>& outputs, int result_attempt, double at) override;
  void request_cancel(const std::string& id) override;
  void remove(const std::string& id) override;
  std::vector<Job> unfinished() override;
  std::vector<std::string> finished_before(double before) override;
  std::map<std::string, int64_t> count_by_state() override;

  // JobQueue
  SubmitAnswer submit(const Job& job, int capacity) override;
  std::optional<std::pair<Job, Lease>> claim(const std::string& owner, double lease_seconds) override;
  std::vector<HeartbeatAnswer> heartbeat(const std::vector<Lease>& leases, double lease_seconds) override;
  bool progress(const Lease& lease, const std::string& stage, double fraction,
                const nlohmann::json& stage_seconds) override;
  bool complete(const Lease& lease, JobState state, const std::optional<JobError>& error,
                const std::vector<std::string>& outputs) override;
  bool release(const Lease& lease) override;
  ReapResult reap(int max_attempts) override;
  bool cancel_queued(const std::string& id) override;
  void notify_cancel(const std::string& id) override;
  std::vector<std::string> expire(double ttl_seconds) override;
  int64_t queued() override;

 private:
  PgPool& pool_;
  PgPool& advisory_;
};

// Heartbeats and progress lines are committed without waiting for the WAL
// flush: losing the last ones in a database crash only makes a lease look
// older (at worst a job runs again, which owner-conditioned writes make
// safe) or a progress bar step back. Claims, outcomes, submissions and
// cancels stay synchronous. One fsync fewer per job (soupuv-bench store).
inline constexpr const char* kAdvisoryWrites = "SET synchronous_commit = off";

// NOTIFY channels: a job was queued (idle workers claim), a cancel was
// requested (the node running it kills its worker). Payload: the job id.
inline constexpr const char* kJobsChannel = "soupuv_jobs";
inline constexpr const char* kCancelChannel = "soupuv_cancel";

}  // namespace soupuv::server
