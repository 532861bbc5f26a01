// JobStore decorator: every job's current row is kept in memory, so the hot
// read paths (GET /v1/jobs/{id} polls, /metrics counts) never touch SQLite and
// never wait behind a writer — a WAL commit, a checkpoint's fsync or the
// supervisor's progress updates. Writes go to the durable store first; then
// the row is read back from it and replaces the memory copy, so the snapshot
// holds exactly what a restart would load (no second copy of the store's
// update rules here).
//
// Input: the durable store (owned). Startup cost: one pass over all rows (jobs
// live until their TTL, so the table stays small).
#include <algorithm>
#include <mutex>
#include <shared_mutex>
#include <unordered_map>

#include "soupuv/server/job_store.h"

namespace soupuv::server {
namespace {

class SnapshotJobStore final : public JobStore {
 public:
  explicit SnapshotJobStore(std::unique_ptr<JobStore> durable) : durable_(std::move(durable)) {
    std::string cursor;
    do {
      JobPage page = durable_->list(std::nullopt, 100, cursor, std::nullopt);
      for (auto& j : page.jobs) jobs_.emplace(j.id, std::move(j));
      cursor = page.next_cursor;
    } while (!cursor.empty());
  }

  std::optional<Job> create_or_get_by_key(const Job& job) override {
    std::lock_guard w(write_mu_);
    auto stored = durable_->create_or_get_by_key(job);
    if (stored) put(*stored);
    return stored;
  }

  std::optional<Job> get(const std::string& id) override {
    std::shared_lock r(mu_);
    auto it = jobs_.find(id);
    if (it == jobs_.end()) return std::nullopt;
    return it->second;
  }

  // Paging by the store's cursor stays in SQLite (rare, and ordered by seq).
  JobPage list(std::optional<JobState> state, int limit, const std::string& cursor,
               const std::optional<std::string>& tenant) override {
    return durable_->list(state, limit, cursor, tenant);
  }

  void mark_running(const std::string& id, double at) override {
    std::lock_guard w(write_mu_);
    durable_->mark_running(id, at);
    refresh(id);
  }

  void requeue(const std::string& id) override {
    std::lock_guard w(write_mu_);
    durable_->requeue(id);
    refresh(id);
  }

  void update_progress(const std::string& id, const std::string& stage, double fraction,
                       const nlohmann::json& stage_seconds) override {
    std::lock_guard w(write_mu_);
    durable_->update_progress(id, stage, fraction, stage_seconds);
    refresh(id);
  }

  void finish(const std::string& id, JobState state, const std::optional<JobError>& error,
              const std::vector<std::string>& outputs, int result_attempt, double at) override {
    std::lock_guard w(write_mu_);
    durable_->finish(id, state, error, outputs, result_attempt, at);
    refresh(id);
  }

  void request_cancel(const std::string& id) override {
    std::lock_guard w(write_mu_);
    durable_->request_cancel(id);
    refresh(id);
  }

  void remove(const std::string& id) override {
    std::lock_guard w(write_mu_);
    durable_->remove(id);
    std::unique_lock x(mu_);
    jobs_.erase(id);
  }

  std::vector<Job> unfinished() override { return durable_->unfinished(); }
  std::vector<std::string> finished_before(double before) override { return durable_->finished_before(before); }

  std::map<std::string, int64_t> count_by_state() override {
    std::map<std::string, int64_t> out;
    for (JobState st : {JobState::queued, JobState::running, JobState::succeeded, JobState::failed,
                        JobState::canceled})
      out[to_string(st)] = 0;
    std::shared_lock r(mu_);
    for (const auto& [id, j] : jobs_) ++out[to_string(j.state)];
    return out;
  }

 private:
  // Caller holds write_mu_, so no other write to this id interleaves.
  void refresh(const std::string& id) {
    auto fresh = durable_->get(id);
    std::unique_lock x(mu_);
    if (fresh) jobs_[id] = std::move(*fresh);
    else jobs_.erase(id);
  }
  void put(const Job& j) {
    std::unique_lock x(mu_);
    jobs_[j.id] = j;
  }

  std::unique_ptr<JobStore> durable_;
  std::mutex write_mu_;            // serialises durable write + snapshot update
  mutable std::shared_mutex mu_;   // guards jobs_; readers share it
  std::unordered_map<std::string, Job> jobs_;
};

}  // namespace

std::unique_ptr<JobStore> with_memory_snapshot(std::unique_ptr<JobStore> durable) {
  return std::make_unique<SnapshotJobStore>(std::move(durable));
}

}  // namespace soupuv::server
