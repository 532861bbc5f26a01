#include "soupuv/server/scheduler.h"

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>

#include "soupuv/openmp_wait.h"
#include "soupuv/server/log.h"
#include "soupuv/server/result_blobs.h"
#include "soupuv/server/sandbox.h"
#include "soupuv/server/storage.h"
#include "soupuv/server/worker_process.h"

namespace soupuv::server {
namespace fs = std::filesystem;
namespace {

// Result files a worker may produce, in the job's work/ directory.
const std::vector<std::string>& output_names() {
  static const std::vector<std::string> names = {"result.glb", "diagnostics.json", "uv-layout.png",
                                                 "proxy.glb", "field-lines.glb"};
  return names;
}

// Diagnostics name the worker's files by absolute path; clients must not learn
// the server's layout, so every string inside the data directory becomes its
// file name.
void scrub_paths(nlohmann::json& j, const std::string& root) {
  if (j.is_object() || j.is_array()) {
    for (auto& v : j) scrub_paths(v, root);
  } else if (j.is_string()) {
    const std::string& s = j.get_ref<const std::string&>();
    if (s.rfind(root, 0) == 0) j = fs::path(s).filename().string();
  }
}

// Stage names come from the worker; keep them safe as metric labels and JSON.
std::string clean_stage(const std::string& s) {
  std::string out;
  for (char c : s.substr(0, 48))
    out += (std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-') ? c : '_';
  return out;
}

}  // namespace

WorkerVerdict classify_outcome(const ProcessOutcome& o, const std::string& reason, const Config& config) {
  if (!o.started) return {JobState::failed, JobError{"worker_unavailable", 503, o.start_error}};
  if (o.canceled) return {JobState::canceled, std::nullopt};
  if (o.output_exceeded)
    return {JobState::failed,
            JobError{"output_limit", 500, "the worker wrote more than 1 MiB to stdout, where it should write nothing"}};
  if (o.timed_out)
    return {JobState::failed,
            JobError{"timeout", 504, "job exceeded its wall-clock limit of " +
                                         std::to_string(config.job_timeout_s) + " s"}};
  if (o.signal != 0) {
    // RLIMIT_CPU: the job's own budget, the same on every run.
    if (o.signal == SIGXCPU)
      return {JobState::failed, JobError{"resource_limit", 500, "worker stopped by signal " +
                                                                   std::to_string(o.signal) + " (CPU-time limit)"}};
    if (o.signal == SIGXFSZ)
      return {JobState::failed, JobError{"resource_limit", 500, "worker stopped by signal " + std::to_string(o.signal) +
                                                                   " (file-size limit, --worker-max-file-mb)"}};
    // SIGKILL we did not send: the kernel's OOM killer (or an operator), which
    // depends on what else ran at the time, so another attempt may succeed.
    if (o.signal == SIGKILL)
      return {JobState::failed,
              JobError{"resource_limit", 500, "worker killed by signal 9 (out of memory?)"}, true};
    return {JobState::failed, JobError{"crashed", 500, "worker crashed with signal " + std::to_string(o.signal)},
            true};
  }
  if (o.exit_code == 0) return {JobState::succeeded, std::nullopt};
  if (o.exit_code == 130) return {JobState::canceled, std::nullopt};
  std::string detail = reason.empty() ? "worker exited with code " + std::to_string(o.exit_code) : reason;
  // The CLI's exit codes mirror soupuv::ErrorCode (see `soupuv --help`); the
  // reason text is the loader's/pipeline's own sentence.
  switch (o.exit_code) {  // core/apps/cli.h `Exit`
    case 2: return {JobState::failed, JobError{"worker_usage", 500, "the worker refused its arguments: " + detail}};
    case 3: return {JobState::failed, JobError{"invalid_input", 400, detail}};
    case 4: return {JobState::failed, JobError{"unsupported", 422, detail}};
    case 5: return {JobState::failed, JobError{"limit_exceeded", 413, detail}};
    case 6: return {JobState::failed, JobError{"no_triangles", 422, detail}};
    case 7: return {JobState::failed, JobError{"not_built", 501, detail}};
    case 8: return {JobState::failed, JobError{"io_error", 500, detail}};
    case 127: return {JobState::failed, JobError{"worker_unavailable", 503, detail}};
    case kSandboxFailedExit: return {JobState::failed, JobError{"sandbox_failed", 500, detail}};
    default: return {JobState::failed, JobError{"internal", 500, detail}};
  }
}

Scheduler::Scheduler(const Config& config, std::string worker_bin, WorkerCapabilities caps,
                     JobStore& store, const DataDir& data, Metrics& metrics, BlobStore& blobs, JobQueue* queue,
                     std::string node_id)
    : config_(config), worker_bin_(std::move(worker_bin)), caps_(std::move(caps)), store_(store),
      data_(data), metrics_(metrics), blobs_(blobs), shared_(queue), node_id_(std::move(node_id)) {}

Scheduler::~Scheduler() { stop(); }

void Scheduler::start() {
  for (int i = 0; i < config_.workers; ++i) {
    if (shared_) threads_.emplace_back([this, i] { claim_loop(i); });
    else threads_.emplace_back([this] { worker_loop(); });
  }
  if (shared_) heartbeat_ = std::thread([this] { heartbeat_loop(); });
}

void Scheduler::stop() {
  {
    std::lock_guard lock(mu_);
    if (stopping_ && threads_.empty()) return;
    stopping_ = true;
    for (auto& [id, flag] : running_) flag->store(true);
  }
  cv_.notify_all();
  for (auto& t : threads_)
    if (t.joinable()) t.join();
  threads_.clear();
  if (heartbeat_.joinable()) heartbeat_.join();
}

Scheduler::Enqueue Scheduler::enqueue(const std::string& id) {
  {
    std::lock_guard lock(mu_);
    if (stopping_) return Enqueue::stopping;
    if (int(queue_.size()) >= config_.queue_capacity) return Enqueue::full;
    queue_.push_back(id);
  }
  cv_.notify_one();
  return Enqueue::accepted;
}

bool Scheduler::has_room() const {
  if (shared_) {
    {
      std::lock_guard lock(mu_);
      if (stopping_) return false;
    }
    return int(queue_depth()) < config_.queue_capacity;
  }
  std::lock_guard lock(mu_);
  return !stopping_ && int(queue_.size()) < config_.queue_capacity;
}

size_t Scheduler::recover() {
  // Shared queue: nothing is this process's to recover. Jobs a dead process
  // held come back when their leases expire (job_reaper.h), on any node.
  if (shared_) return 0;
  auto jobs = store_.unfinished();
  size_t requeued = 0;
  for (const auto& j : jobs) {
    // A job running when the server died has used an attempt (mark_running
    // counted it); one that keeps taking the server down must not loop forever.
    if (j.state == JobState::running && j.attempts >= config_.max_attempts) {
      const std::string detail = "the job was interrupted on each of its " + std::to_string(j.attempts) +
                                 " attempts (the server stopped or was killed while it ran)";
      if (!store_write("finish", [&] {
            store_.finish(j.id, JobState::failed, JobError{"interrupted", 500, detail}, {}, 0, now_seconds());
          }))
        continue;  // stays running in the store; the next start decides again
      remove_work_dir(j.id);
      metrics_.job_finished("failed");
      log::warn("job failed at recovery", {{"job", j.id}, {"attempts", j.attempts}});
      continue;
    }
    {
      std::lock_guard lock(mu_);
      queue_.push_back(j.id);
    }
    ++requeued;
    log::info("job recovered", {{"job", j.id}, {"was", to_string(j.state)}, {"attempts", j.attempts}});
  }
  cv_.notify_all();
  return requeued;
}

bool Scheduler::cancel(const std::string& id) {
  if (shared_) {
    // Queued anywhere: canceled in the database at once. Running here: the
    // flag. Running elsewhere: that node hears it (NOTIFY now, its next
    // heartbeat at the latest: the flag is in the row).
    if (shared_->cancel_queued(id)) {
      metrics_.job_finished("canceled");
      return true;
    }
    if (cancel_local(id)) return true;
    shared_->notify_cancel(id);
    return false;
  }
  std::lock_guard lock(mu_);
  for (auto it = queue_.begin(); it != queue_.end(); ++it)
    if (*it == id) {
      queue_.erase(it);
      store_.finish(id, JobState::canceled, std::nullopt, {}, 0, now_seconds());
      metrics_.job_finished("canceled");
      if (on_finish_) on_finish_(id);
      return true;
    }
  auto r = running_.find(id);
  if (r != running_.end()) {
    r->second->store(true);
    return true;
  }
  return false;
}

bool Scheduler::cancel_local(const std::string& id) {
  std::lock_guard lock(mu_);
  auto r = running_.find(id);
  if (r == running_.end()) return false;
  r->second->store(true);
  return true;
}

void Scheduler::wake() {
  {
    std::lock_guard lock(mu_);
    ++wake_seq_;
  }
  cv_.notify_all();
}

size_t Scheduler::queue_depth() const {
  if (shared_) {
    // Every poll of a queued job and every submission asks (Retry-After,
    // capacity): one COUNT a second per node is plenty for a hint, and the
    // exact capacity check is the database's own (JobQueue::submit).
    const double now = std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
    std::lock_guard lock(depth_mu_);
    if (depth_at_ < 0 || now - depth_at_ >= 1.0) {
      depth_at_ = now;
      try {
        depth_ = size_t(shared_->queued());
      } catch (const std::exception& e) {
        // The database is away: the last known depth stands (a submission
        // then fails with 503 storage-unavailable on its own insert).
        log::warn("queue depth unavailable", {{"error", e.what()}});
      }
    }
    return depth_;
  }
  std::lock_guard lock(mu_);
  return queue_.size();
}

int Scheduler::busy_workers() const {
  std::lock_guard lock(mu_);
  return int(running_.size());
}

bool Scheduler::store_write(const char* what, const std::function<void()>& write) {
  std::string last;
  // Embedded: about 3 s (SQLITE_BUSY, a disk the sweeper frees). Shared
  // queue: up to half a lease, long enough for a PostgreSQL restart, short
  // enough that the lease (renewed meanwhile if the database is back) holds.
  const double patience = shared_ ? std::max(3.0, config_.lease_seconds / 2.0) : 3.0;
  double waited = 0;
  for (int delay_ms = 100;; delay_ms = std::min(delay_ms * 2, 1600)) {
    try {
      write();
      return true;
    } catch (const std::exception& e) {
      last = e.what();
    }
    if (waited >= patience) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(delay_ms));
    waited += delay_ms / 1000.0;
  }
  log::error("job store write failed", {{"write", what}, {"error", last}});
  return false;
}

void Scheduler::remove_work_dir(const std::string& id) noexcept {
  if (!is_valid_job_id(id)) return;
  std::error_code ec;
  fs::remove_all(data_.root() / "jobs" / id / "work", ec);
}

void Scheduler::worker_loop() {
  for (;;) {
    std::string id;
    {
      std::unique_lock lock(mu_);
      cv_.wait(lock, [&] { return stopping_ || !queue_.empty(); });
      if (stopping_) return;
      id = queue_.front();
      queue_.pop_front();
      running_[id] = std::make_shared<std::atomic<bool>>(false);
    }
    // Nothing may escape this thread (std::terminate would take every job
    // down): run_job's errors fail the job, and if even that cannot be
    // recorded the job stays unfinished in the store for the next start.
    bool again = false;
    try {
      again = run_job(id);
    } catch (const std::exception& e) {
      log::error("job supervision failed", {{"job", id}, {"error", e.what()}});
      if (store_write("finish", [&] {
            store_.finish(id, JobState::failed, JobError{"internal", 500, "server error while running the job"},
                          {}, 0, now_seconds());
          })) {
        metrics_.job_finished("failed");
        if (on_finish_) on_finish_(id);
      }
      remove_work_dir(id);
    }
    std::lock_guard lock(mu_);
    running_.erase(id);
    // Only now, with its running_ entry gone, may another thread take it:
    // behind the jobs already waiting, so a poison job cannot monopolise a worker.
    if (again && !stopping_) {
      queue_.push_back(id);
      cv_.notify_one();
    }
  }
}

void Scheduler::claim_loop(int slot) {
  const std::string owner = node_id_ + "/" + std::to_string(slot);
  const auto poll = std::chrono::milliseconds(config_.poll_interval_ms);
  uint64_t seen = 0;
  double last_error_log = -1e9;
  for (;;) {
    {
      std::lock_guard lock(mu_);
      if (stopping_) return;
      seen = wake_seq_;
    }
    std::optional<std::pair<Job, Lease>> claimed;
    try {
      claimed = shared_->claim(owner, config_.lease_seconds);
    } catch (const std::exception& e) {
      // The database is away (restarting, unreachable): keep polling. Logged
      // at most every 10 s per worker.
      if (now_seconds() - last_error_log > 10) {
        log::warn("cannot claim a job", {{"error", e.what()}});
        last_error_log = now_seconds();
      }
    }
    if (!claimed) {
      std::unique_lock lock(mu_);
      cv_.wait_for(lock, poll, [&] { return stopping_ || wake_seq_ != seen; });
      continue;
    }
    const Job& job = claimed->first;
    const Lease& lease = claimed->second;
    {
      std::lock_guard lock(mu_);
      running_[job.id] = std::make_shared<std::atomic<bool>>(false);
      leases_[job.id] = lease;
    }
    try {
      run_leased(job, lease);
    } catch (const StorageUnavailable& e) {
      // The database went away mid-attempt (its input or results could not
      // be moved): not the job's fault. Give it back for another attempt;
      // if even that cannot be written, its lease expires and the reaper
      // does it (both bounded by --max-attempts).
      log::warn("job attempt interrupted by the database; released", {{"job", job.id}, {"error", e.what()}});
      store_write("requeue", [&] { shared_->release(lease); });
    } catch (const std::exception& e) {
      log::error("job supervision failed", {{"job", job.id}, {"error", e.what()}});
      bool done = false;
      if (store_write("finish", [&] {
            done = shared_->complete(lease, JobState::failed,
                                    JobError{"internal", 500, "server error while running the job"}, {});
          }) && done)
        metrics_.job_finished("failed");
    }
    std::error_code ec;
    fs::remove_all(data_.job(job.id), ec);  // local scratch only: the job's files live in the blob store
    std::lock_guard lock(mu_);
    running_.erase(job.id);
    leases_.erase(job.id);
    lease_lost_.erase(job.id);
  }
}

void Scheduler::heartbeat_loop() {
  // Several beats per lease, so one or two lost to a database restart do not
  // let the lease lapse.
  const auto period = std::chrono::milliseconds(int(std::max(0.2, config_.lease_seconds / 5.0) * 1000));
  std::unique_lock lock(mu_);
  while (!stopping_) {
    cv_.wait_for(lock, period, [&] { return stopping_; });
    if (stopping_) break;
    std::vector<Lease> leases;
    for (const auto& [id, l] : leases_) leases.push_back(l);
    if (leases.empty()) continue;
    lock.unlock();
    std::vector<HeartbeatAnswer> answers;
    try {
      answers = shared_->heartbeat(leases, config_.lease_seconds);
    } catch (const std::exception& e) {
      log::warn("lease heartbeat failed", {{"error", e.what()}, {"leases", leases.size()}});
    }
    lock.lock();
    for (const auto& a : answers) {
      auto r = running_.find(a.id);
      if (r == running_.end()) continue;
      if (!a.held) {
        // Another node has (or will have) this job: stop the worker here, its
        // result could not be recorded anyway.
        if (!lease_lost_[a.id]) log::warn("lease lost; stopping the worker", {{"job", a.id}});
        lease_lost_[a.id] = true;
        r->second->store(true);
        metrics_.lease_lost();
      } else if (a.cancel_requested) {
        r->second->store(true);
      }
    }
  }
}

struct Scheduler::Attempt {
  ProcessOutcome outcome;
  WorkerVerdict verdict;
  std::vector<std::string> outputs;
  nlohmann::json stage_seconds;
};

bool Scheduler::run_job(const std::string& id) {
  auto job = store_.get(id);
  if (!job || is_finished(job->state)) return false;
  std::shared_ptr<std::atomic<bool>> cancel;
  {
    std::lock_guard lock(mu_);
    cancel = running_[id];
  }
  if (job->cancel_requested) {
    if (store_write("finish", [&] { store_.finish(id, JobState::canceled, std::nullopt, {}, 0, now_seconds()); })) {
      metrics_.job_finished("canceled");
      if (on_finish_) on_finish_(id);
    }
    return false;
  }
  // A worker binary being replaced (upgrade, rebuild) is briefly missing: wait
  // for it rather than failing the job; after 30 s the job fails with a reason.
  // (A plain sleep: waiting on cv_ here could swallow an enqueue's notify_one.)
  for (int i = 0; i < 60 && access(worker_bin_.c_str(), X_OK) != 0; ++i) {
    {
      std::lock_guard lock(mu_);
      if (stopping_) return false;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
  }
  const fs::path work = data_.job(id) / "work";
  fs::remove_all(work);  // a re-run after restart starts clean: jobs are idempotent
  fs::create_directories(work);
  // Without a record of the attempt the run would not count (nor its result
  // be recorded): put the job back at the end of the queue and try again
  // after the next jobs; store_write's retries are the back-off.
  if (!store_write("mark_running", [&] { store_.mark_running(id, now_seconds()); })) return true;
  const int attempt_no = job->attempts + 1;  // mark_running counted it
  log::info("job started", {{"job", id}, {"attempt", attempt_no}});

  Attempt a = attempt(
      *job, attempt_no, *cancel,
      [&](const std::string& stage, double f, const nlohmann::json& secs) { store_.update_progress(id, stage, f, secs); },
      [] { return true; });
  WorkerVerdict& verdict = a.verdict;
  // Server shutdown is not a user's cancel: leave the job running so that the
  // next start runs it again.
  {
    std::lock_guard lock(mu_);
    if (stopping_ && verdict.state == JobState::canceled) {
      auto fresh = store_.get(id);
      if (fresh && !fresh->cancel_requested) return false;
    }
  }
  if (verdict.retryable && verdict.error) {
    if (attempt_no < config_.max_attempts) {
      fs::remove_all(work);
      log::warn("job attempt failed, retrying",
                {{"job", id}, {"attempt", attempt_no}, {"error", verdict.error->detail}});
      return store_write("requeue", [&] { store_.requeue(id); });
    }
    if (attempt_no > 1) verdict.error->detail += " (on each of " + std::to_string(attempt_no) + " attempts)";
  }
  fs::remove_all(work);
  // If the outcome cannot be recorded the job stays running in the store and
  // the next start runs it again (bounded by --max-attempts).
  if (!store_write("finish",
                   [&] { store_.finish(id, verdict.state, verdict.error, a.outputs, attempt_no, now_seconds()); }))
    return false;
  // Results of earlier runs cut short by a restart between storing them and
  // recording their outcome: never the job's result now.
  discard_losing_attempts(blobs_, id, attempt_no);
  metrics_.job_finished(to_string(verdict.state));
  if (on_finish_) on_finish_(id);
  nlohmann::json fields = {{"job", id}, {"state", to_string(verdict.state)}, {"seconds", a.outcome.seconds},
                           {"stage_seconds", a.stage_seconds}};
  if (verdict.error) fields["error"] = verdict.error->detail;
  log::info("job finished", fields);
  return false;
}

void Scheduler::run_leased(const Job& job, const Lease& lease) {
  const std::string& id = job.id;
  std::shared_ptr<std::atomic<bool>> cancel;
  {
    std::lock_guard lock(mu_);
    cancel = running_[id];
  }
  auto lost = [&] {
    std::lock_guard lock(mu_);
    return lease_lost_[id];
  };
  // This attempt's result blobs, once they cannot be the job's result: no one
  // reads them (result_blobs.h), so they go now rather than at the TTL. A
  // complete() refused on a retry may follow our own first one, committed
  // with its answer lost: the row says whose result the job has.
  auto discard_own = [&] {
    try {
      auto now = store_.get(id);
      if (now && now->result_attempt == lease.attempt) return;
    } catch (const std::exception&) {
      return;  // unknown: left to the TTL sweep
    }
    discard_attempt(blobs_, id, lease.attempt);
  };
  auto complete = [&](JobState state, const std::optional<JobError>& error, const std::vector<std::string>& outputs) {
    bool held = false;
    if (!store_write("finish", [&] { held = shared_->complete(lease, state, error, outputs); })) return false;
    if (held) {
      // Attempts that lost the job may have stored results before learning it.
      discard_losing_attempts(blobs_, id, lease.attempt);
      return true;
    }
    log::warn("lease lost before the outcome was recorded; another attempt owns the job", {{"job", id}});
    if (!outputs.empty()) discard_own();
    return false;
  };
  if (job.cancel_requested) {
    if (complete(JobState::canceled, std::nullopt, {})) metrics_.job_finished("canceled");
    return;
  }
  log::info("job started", {{"job", id}, {"attempt", lease.attempt}, {"owner", lease.owner}});
  // The input comes from the blob store into this node's scratch directory,
  // where the worker's sandbox reads it like an embedded job's.
  const fs::path dir = data_.job(id);
  fs::remove_all(dir);
  fs::create_directories(dir / "work");
  for (const auto& name : blobs_.names(id))
    if (name == job.input_file || name == "texture.png" || name == "texture.jpg" || name.rfind("model/", 0) == 0) {
      fs::create_directories((dir / name).parent_path());  // a folder upload's subfolders
      blobs_.get(id, name, dir / name);
    }
  if (!fs::exists(dir / job.input_file)) {
    if (complete(JobState::failed, JobError{"internal", 500, "the job's input is missing from the store"}, {}))
      metrics_.job_finished("failed");
    return;
  }

  Attempt a = attempt(
      job, lease.attempt, *cancel,
      [&](const std::string& stage, double f, const nlohmann::json& secs) {
        if (!shared_->progress(lease, stage, f, secs)) {
          std::lock_guard lock(mu_);
          lease_lost_[id] = true;
          cancel->store(true);
        }
      },
      // Results are stored only while the lease looks ours, which spares
      // storing files that cannot win. It is not what keeps a re-run's
      // result safe (the lease can be lost right after this check): that is
      // the per-attempt blob names and complete() naming the attempt.
      [&] {
        if (lost()) return false;
        auto hb = shared_->heartbeat({lease}, config_.lease_seconds);
        return !hb.empty() && hb[0].held;
      });
  WorkerVerdict& verdict = a.verdict;
  if (lost()) {
    log::warn("attempt abandoned: its lease was lost", {{"job", id}, {"attempt", lease.attempt}});
    if (!a.outputs.empty()) discard_own();
    return;
  }
  {
    std::lock_guard lock(mu_);
    if (stopping_ && verdict.state == JobState::canceled) {
      // Server shutdown, not a client's cancel: give the job back now, so
      // another node runs it without waiting for the lease to expire.
      auto fresh = store_.get(id);
      if (fresh && !fresh->cancel_requested) {
        store_write("requeue", [&] { shared_->release(lease); });
        log::info("job released at shutdown", {{"job", id}});
        return;
      }
    }
  }
  if (verdict.retryable && verdict.error) {
    if (lease.attempt < config_.max_attempts) {
      log::warn("job attempt failed, retrying",
                {{"job", id}, {"attempt", lease.attempt}, {"error", verdict.error->detail}});
      store_write("requeue", [&] { shared_->release(lease); });
      return;
    }
    if (lease.attempt > 1) verdict.error->detail += " (on each of " + std::to_string(lease.attempt) + " attempts)";
  }
  if (!complete(verdict.state, verdict.error, a.outputs)) return;
  metrics_.job_finished(to_string(verdict.state));
  if (on_finish_) on_finish_(id);
  nlohmann::json fields = {{"job", id}, {"state", to_string(verdict.state)}, {"seconds", a.outcome.seconds},
                           {"stage_seconds", a.stage_seconds}, {"attempt", lease.attempt}};
  if (verdict.error) fields["error"] = verdict.error->detail;
  log::info("job finished", fields);
}

Scheduler::Attempt Scheduler::attempt(const Job& job, int attempt_no, std::atomic<bool>& cancel,
                                      const ProgressWrite& progress, const std::function<bool()>& may_store) {
  const std::string& id = job.id;
  const fs::path dir = data_.job(id);
  const fs::path work = dir / "work";
  std::vector<std::string> argv = {worker_bin_, "map", (dir / job.input_file).string(), "-o",
                                   (work / "result.glb").string()};
  auto add = [&](const std::string& flag, const std::string& value) {
    if (!caps_.has(flag)) return;
    argv.push_back(flag);
    if (!value.empty()) argv.push_back(value);
  };
  add("--diagnostics", (work / "diagnostics.json").string());
  add("--progress", "json");
  add("--uv-layout", (work / "uv-layout.png").string());
  add("--threads", std::to_string(config_.threads_per_job()));
  add("--cache-dir", data_.cache().string());
  // (The CLI has no disk budget flag: the server prunes cache/ to --cache-size-mb.)
  if (job.params.value("debug_outputs", false)) add("--debug-prefix", (work / "debug").string());
  // Validated at submit (params.cpp); the CLI reads them from a file.
  if (job.params.contains("seam_hints") && job.params["seam_hints"].is_array()) {
    write_file_atomic(work / "seam_hints.json", job.params["seam_hints"].dump());
    add("--seam-hints", (work / "seam_hints.json").string());
  }
  // The sandbox (sandbox.h): the worker reads its input and texture, writes
  // only work/ (its scratch directory and cwd) and the shared field cache.
  SandboxPaths paths;
  paths.program = worker_bin_;
  // A folder upload (model/...): the model and every file beside or below it.
  paths.read_files.push_back((dir / job.input_file).string());
  if (job.input_file.rfind("model/", 0) == 0) {
    std::error_code ec;
    for (auto it = fs::recursive_directory_iterator(dir / "model", ec); !ec && it != fs::recursive_directory_iterator();
         it.increment(ec))
      if (it->is_regular_file(ec) && !it->is_symlink(ec) && it->path() != dir / job.input_file)
        paths.read_files.push_back(it->path().string());
  }
  for (const char* tex : {"texture.png", "texture.jpg"})
    if (fs::exists(dir / tex)) {
      add("--texture", (dir / tex).string());
      paths.read_files.push_back((dir / tex).string());
    }
  paths.read_write = {work.string(), data_.cache().string()};
  for (auto& f : params_to_flags(job.params, caps_)) argv.push_back(f);

  ProcessLimits limits;
  limits.address_space_bytes = config_.worker_memory_mb << 20;
  limits.wall_seconds = config_.job_timeout_s;
  // CPU time is summed over threads: allow the wall budget on every thread.
  limits.cpu_seconds = int64_t(config_.job_timeout_s) * config_.threads_per_job() + 10;
  std::string sandbox_error;
  bool confined = confine_worker(config_, paths, work.string(), limits, sandbox_error);
  RulesetCloser closer{limits.landlock_ruleset};
  const std::vector<std::string> env = worker_environment(
      work.string(), config_.worker_env, {"OMP_NUM_THREADS=" + std::to_string(config_.threads_per_job()),
       std::string("OMP_WAIT_POLICY=") + kOpenMpWaitPolicy});

  std::string stage, last_reason;
  double stage_started = now_seconds(), last_write = 0;
  nlohmann::json stage_seconds = nlohmann::json::object();
  auto on_line = [&](const std::string& line) {
    if (line.rfind("soupuv: ", 0) == 0) {
      last_reason = line.substr(8, 500);
      return;
    }
    auto j = nlohmann::json::parse(line, nullptr, false);
    if (!j.is_object() || !j.contains("stage") || !j["stage"].is_string()) return;
    std::string s = clean_stage(j["stage"].get<std::string>());
    // The worker's text is not trusted to be well formed: a fraction that is
    // not a number counts as 0 (json::value would throw on it).
    double f = j.contains("fraction") && j["fraction"].is_number() ? j["fraction"].get<double>() : 0.0;
    if (!std::isfinite(f)) f = 0;
    double now = now_seconds();
    if (s != stage) {
      if (!stage.empty()) {
        double secs = now - stage_started;
        stage_seconds[stage] = stage_seconds.value(stage, 0.0) + secs;
        metrics_.stage_seconds(stage, secs);
      }
      stage = s;
      stage_started = now;
      last_write = 0;  // a new stage is always worth recording
    }
    // Progress is chatty; the store needs ~5 Hz at most. A shared database
    // takes every worker's lines: 1 Hz there, the rate clients poll at
    // (Retry-After: 1 while running), so a fleet's progress stays a small
    // fraction of what the queue can write (server/README.md, Scale-out).
    if (now - last_write >= (shared_ ? 1.0 : 0.2)) {
      last_write = now;
      // Progress is advisory: a failed write must not stop the job.
      try {
        progress(stage, std::clamp(f, 0.0, 1.0), stage_seconds);
      } catch (const std::exception& e) {
        log::warn("progress not recorded", {{"job", id}, {"error", e.what()}});
      }
    }
  };
  Attempt a;
  if (confined) {
    a.outcome = run_process(argv, env, limits, cancel, on_line);
  } else {  // fail closed: an untrusted model is never parsed unconfined by accident
    log::error("worker sandbox could not be built", {{"job", id}, {"error", sandbox_error}});
    a.outcome.started = false;
    a.outcome.start_error = "the worker sandbox could not be set up";
  }
  if (!stage.empty()) {
    double secs = now_seconds() - stage_started;
    stage_seconds[stage] = stage_seconds.value(stage, 0.0) + secs;
    metrics_.stage_seconds(stage, secs);
    try {
      progress(stage, 1.0, stage_seconds);
    } catch (const std::exception& e) {
      log::warn("progress not recorded", {{"job", id}, {"error", e.what()}});
    }
  }
  a.stage_seconds = stage_seconds;
  write_file_atomic(dir / "worker.log", a.outcome.stderr_tail);

  a.verdict = classify_outcome(a.outcome, last_reason, config_);
  WorkerVerdict& verdict = a.verdict;
  if (verdict.state == JobState::succeeded) {
    if (!fs::exists(work / "result.glb")) {
      verdict = {JobState::failed, JobError{"internal", 500, "worker exited 0 without writing a result"}};
    } else if (may_store()) {
      // --debug-prefix names: debug.proxy.glb, debug.lines.glb, debug.uv.png.
      const std::pair<const char*, const char*> debug_names[] = {
          {"debug.proxy.glb", "proxy.glb"}, {"debug.lines.glb", "field-lines.glb"}, {"debug.uv.png", "uv-layout.png"}};
      for (const auto& [from, to] : debug_names)
        if (fs::exists(work / from)) fs::rename(work / from, work / to);
      // Diagnostics name the worker's files by absolute path: scrubbed before
      // they are stored, so no reader ever sees the server's layout.
      if (fs::exists(work / "diagnostics.json")) {
        auto d = nlohmann::json::parse(read_file(work / "diagnostics.json", 64 << 20), nullptr, false);
        if (!d.is_discarded()) {
          scrub_paths(d, data_.root().string());
          write_file_atomic(work / "diagnostics.json", d.dump(2));
        }
        if (d.is_object() && d.contains("cache") && d["cache"].is_object() && d["cache"].contains("hits") &&
            d["cache"]["hits"].is_number_integer())
          metrics_.cache_hits(d["cache"]["hits"].get<int64_t>());
      }
      for (const auto& name : output_names())
        if (fs::exists(work / name)) {
          blobs_.put(id, attempt_blob(attempt_no, name), work / name);
          a.outputs.push_back(name);
        }
    }
  }
  return a;
}

}  // namespace soupuv::server
