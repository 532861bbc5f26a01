// Bounded FIFO queue + N worker threads, each supervising one `soupuv map`
// process at a time (worker_process.h). The HTTP threads only enqueue ids.
//
// Capacity counts queued jobs only (running ones hold a worker). Cancel: a
// queued job is dropped from the queue; a running one gets SIGTERM (the CLI's
// cancel flag), then SIGKILL after a grace period. Results are moved from the
// job's work/ directory into place with fsync + rename, so a reader sees a
// whole file or none.
//
// With a shared queue (--database-url, job_queue.h) there is no local FIFO:
// each worker thread claims the oldest queued job of the whole service as a
// lease, a heartbeat thread renews the leases of the jobs running here and
// learns of cancels requested on any node, and every write is conditioned on
// the lease. Inputs come from and results go to the BlobStore, each attempt's
// results under names of their own; the lease-conditioned outcome names the
// attempt whose results are the job's (result_blobs.h).
#pragma once

#include <atomic>
#include <condition_variable>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "soupuv/server/blob_store.h"
#include "soupuv/server/config.h"
#include "soupuv/server/files.h"
#include "soupuv/server/job_queue.h"
#include "soupuv/server/job_store.h"
#include "soupuv/server/metrics.h"
#include "soupuv/server/params.h"

namespace soupuv::server {

class Scheduler {
 public:
  // `queue`: the shared queue (nullptr: the embedded in-memory FIFO).
  // `node_id`: this process in lease owners ("node/slot").
  Scheduler(const Config& config, std::string worker_bin, WorkerCapabilities caps, JobStore& store,
            const DataDir& data, Metrics& metrics, BlobStore& blobs, JobQueue* queue = nullptr,
            std::string node_id = "");
  ~Scheduler();

  void start();
  void stop();  // cancels running jobs' supervision; processes are killed

  enum class Enqueue { accepted, full, stopping };
  Enqueue enqueue(const std::string& id);
  bool has_room() const;
  // Puts every queued/running job from the store back in the queue (ignoring
  // capacity: they were accepted before the restart).
  size_t recover();
  // True if the job was queued or running here.
  bool cancel(const std::string& id);

  // Shared queue: a job may be waiting (a NOTIFY arrived); idle workers claim.
  void wake();
  // Shared queue: a cancel requested on any node; kills the worker if the
  // job runs here. True if it does.
  bool cancel_local(const std::string& id);

  // Queued jobs: this process's FIFO, or the whole service's with a shared
  // queue (counted at most once a second).
  size_t queue_depth() const;
  int busy_workers() const;
  int workers() const { return int(threads_.size()); }
  const WorkerCapabilities& capabilities() const { return caps_; }
  // Called with a job's id once its end (succeeded, failed, canceled) is
  // stored; set before start(). The job-end callbacks hang here.
  void set_on_finish(std::function<void(const std::string&)> f) { on_finish_ = std::move(f); }

 private:
  void worker_loop();
  void claim_loop(int slot);   // shared queue
  void heartbeat_loop();       // shared queue
  std::function<void(const std::string&)> on_finish_;
  // True when the job should run again (a retryable failure, or its start
  // could not be recorded); worker_loop re-queues it once it is off running_.
  bool run_job(const std::string& id);
  // Shared queue: runs a claimed job under its lease.
  void run_leased(const Job& job, const Lease& lease);
  // The part of an attempt both queues share, once its start is recorded:
  // the worker process from argv to verdict, results stored in `blobs_` on
  // success if `may_store()` still agrees, as attempt `attempt_no`'s blobs
  // (result_blobs.h: they become the job's result only when the outcome
  // recorded names that attempt). `progress` records a progress line (in the
  // store, or under the lease).
  struct Attempt;
  using ProgressWrite = std::function<void(const std::string& stage, double fraction, const nlohmann::json& secs)>;
  Attempt attempt(const Job& job, int attempt_no, std::atomic<bool>& cancel, const ProgressWrite& progress,
                  const std::function<bool()>& may_store);
  // Runs a store write, retrying a failing one (SQLITE_BUSY, a disk freed by
  // the sweeper) for a few seconds; false, logged, if it never succeeds.
  bool store_write(const char* what, const std::function<void()>& write);
  void remove_work_dir(const std::string& id) noexcept;

  const Config& config_;
  std::string worker_bin_;
  WorkerCapabilities caps_;
  JobStore& store_;
  const DataDir& data_;
  Metrics& metrics_;

  mutable std::mutex mu_;
  std::condition_variable cv_;
  std::deque<std::string> queue_;
  std::map<std::string, std::shared_ptr<std::atomic<bool>>> running_;  // id -> cancel flag
  bool stopping_ = false;
  std::vector<std::thread> threads_;

  BlobStore& blobs_;
  JobQueue* shared_;  // the shared queue; nullptr: the embedded FIFO above
  std::string node_id_;
  std::map<std::string, Lease> leases_;     // shared queue: leases held here (under mu_)
  std::map<std::string, bool> lease_lost_;  // id -> the heartbeat found the lease gone
  uint64_t wake_seq_ = 0;                   // bumped by wake(); claim loops wait for a change
  std::thread heartbeat_;
  mutable std::mutex depth_mu_;
  mutable double depth_at_ = -1;            // steady seconds of the cached service-wide depth
  mutable size_t depth_ = 0;
};

// How a finished worker process maps to a job state and error (one table).
struct WorkerVerdict {
  JobState state;
  std::optional<JobError> error;
  // A crash or an outside kill: another attempt may succeed (up to --max-attempts).
  bool retryable = false;
};
struct ProcessOutcome;
WorkerVerdict classify_outcome(const ProcessOutcome& outcome, const std::string& last_reason,
                               const Config& config);

}  // namespace soupuv::server
