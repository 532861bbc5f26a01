// The queue of a job store shared by several soupuv-server processes
// (PgJobStore). The embedded default has no such thing: its queue is the
// scheduler's in-memory FIFO over one SQLite file (scheduler.h), which one
// process owns.
//
// A claim is a lease: the job is `running`, owned by `owner` (one worker slot
// of one node) until `lease_until`, which the owner's heartbeat pushes
// forward. Every write a worker makes (progress, finish, requeue) is
// conditioned on still owning the lease of that attempt, so a worker that
// lost its lease (its node paused past the lease, the reaper gave the job to
// another) cannot overwrite the re-run. Every time is the database's clock
// (now()), never a node's: nodes' clocks may disagree, the database's is one.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "soupuv/server/job.h"

namespace soupuv::server {

// Which worker holds a job: the owner string and the attempt number it
// claimed (attempts after the claim). Both must match for a write to land.
struct Lease {
  std::string id;
  std::string owner;
  int attempt = 0;
};

struct HeartbeatAnswer {
  std::string id;
  bool held = false;              // the lease is still this owner's
  bool cancel_requested = false;  // a client asked to cancel (any node)
};

struct ReapResult {
  std::vector<std::string> requeued;  // lease expired, attempts left: queued again
  std::vector<std::string> failed;    // lease expired on the last attempt: failed (`lost`)
};

enum class Admission { accepted, duplicate, full };
struct SubmitAnswer {
  Admission admission = Admission::accepted;
  std::optional<Job> job;  // the new job, or the one the Idempotency-Key names
};

class JobQueue {
 public:
  virtual ~JobQueue() = default;

  // Inserts `job` as queued unless `capacity` jobs are already queued across
  // the service (checked and inserted atomically), or returns the tenant's
  // job with the same Idempotency-Key (not counted against capacity).
  virtual SubmitAnswer submit(const Job& job, int capacity) = 0;
  // The oldest queued job, now running and leased to `owner` for
  // `lease_seconds`; attempts += 1. Never the same job to two claimers
  // (FOR UPDATE SKIP LOCKED). nullopt: nothing queued.
  virtual std::optional<std::pair<Job, Lease>> claim(const std::string& owner, double lease_seconds) = 0;
  // Extends every given lease still held; tells which are lost and which
  // jobs a client asked to cancel.
  virtual std::vector<HeartbeatAnswer> heartbeat(const std::vector<Lease>& leases, double lease_seconds) = 0;
  // Owner-conditioned writes: false when the lease is no longer this
  // owner's (nothing written).
  virtual bool progress(const Lease& lease, const std::string& stage, double fraction,
                        const nlohmann::json& stage_seconds) = 0;
  virtual bool complete(const Lease& lease, JobState state, const std::optional<JobError>& error,
                        const std::vector<std::string>& outputs) = 0;
  virtual bool release(const Lease& lease) = 0;  // back to queued for another attempt
  // Expired leases: re-queued while attempts < max_attempts, else failed
  // with code `lost`. Safe to run on every node at once.
  virtual ReapResult reap(int max_attempts) = 0;
  // A queued job canceled at once (true); a running one is left to its
  // worker, which learns of the cancel from its heartbeat or a notification.
  virtual bool cancel_queued(const std::string& id) = 0;
  virtual void notify_cancel(const std::string& id) = 0;
  // Finished jobs older than `ttl_seconds` by the database clock, deleted
  // with their blobs in one transaction; their ids.
  virtual std::vector<std::string> expire(double ttl_seconds) = 0;
  virtual int64_t queued() = 0;
};

}  // namespace soupuv::server
