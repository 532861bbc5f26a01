// A node that freezes right after its last lease check: a JobQueue in front
// of the real one (PgJobStore) for an in-process Scheduler. When the worker
// slot asks whether its lease still holds before storing a result (the
// scheduler's may_store() heartbeat), the database answers "held" and then
// the slot stops until thaw(), as a node stops in a VM pause, a long GC or a
// partition. While it is frozen the node's heartbeat thread cannot reach the
// database either (its calls throw, as a cut-off connection's do), so the
// lease lapses and another node may take the job. After thaw() the slot goes
// on with the stale "held" answer: exactly the window no lease check closes.
#pragma once

#include <condition_variable>
#include <mutex>
#include <stdexcept>
#include <thread>

#include "soupuv/server/job_queue.h"

namespace soupuv::test {

class FrozenNodeQueue final : public server::JobQueue {
 public:
  explicit FrozenNodeQueue(server::JobQueue& real) : real_(real) {}

  // Blocks until the slot has passed its lease check and frozen; false after
  // `timeout_s` without that.
  bool wait_frozen(double timeout_s) {
    std::unique_lock lock(mu_);
    return cv_.wait_for(lock, std::chrono::duration<double>(timeout_s), [&] { return frozen_; });
  }
  void thaw() {
    std::lock_guard lock(mu_);
    thawed_ = true;
    cv_.notify_all();
  }

  server::SubmitAnswer submit(const server::Job& job, int capacity) override { return real_.submit(job, capacity); }
  std::optional<std::pair<server::Job, server::Lease>> claim(const std::string& owner, double secs) override {
    auto c = real_.claim(owner, secs);
    if (c) {
      std::lock_guard lock(mu_);
      slot_ = std::this_thread::get_id();
    }
    return c;
  }
  std::vector<server::HeartbeatAnswer> heartbeat(const std::vector<server::Lease>& leases, double secs) override {
    std::unique_lock lock(mu_);
    if (std::this_thread::get_id() != slot_ || thawed_) {
      // The heartbeat thread. Under the lock, so that none of its renewals
      // is still in flight once the slot is frozen.
      if (frozen_ && !thawed_) throw std::runtime_error("frozen node: the database is out of reach");
      return real_.heartbeat(leases, secs);
    }
    lock.unlock();
    auto answers = real_.heartbeat(leases, secs);  // the slot's last check: still held
    lock.lock();
    frozen_ = true;
    cv_.notify_all();
    cv_.wait(lock, [&] { return thawed_; });
    return answers;
  }
  bool progress(const server::Lease& l, const std::string& stage, double f, const nlohmann::json& secs) override {
    return real_.progress(l, stage, f, secs);
  }
  bool complete(const server::Lease& l, server::JobState state, const std::optional<server::JobError>& error,
                const std::vector<std::string>& outputs) override {
    return real_.complete(l, state, error, outputs);
  }
  bool release(const server::Lease& l) override { return real_.release(l); }
  server::ReapResult reap(int max_attempts) override { return real_.reap(max_attempts); }
  bool cancel_queued(const std::string& id) override { return real_.cancel_queued(id); }
  void notify_cancel(const std::string& id) override { real_.notify_cancel(id); }
  std::vector<std::string> expire(double ttl) override { return real_.expire(ttl); }
  int64_t queued() override { return real_.queued(); }

 private:
  server::JobQueue& real_;
  std::mutex mu_;
  std::condition_variable cv_;
  std::thread::id slot_;
  bool frozen_ = false, thawed_ = false;
};

}  // namespace soupuv::test
