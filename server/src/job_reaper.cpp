#include "soupuv/server/job_reaper.h"

#include <algorithm>
#include <chrono>

#include "soupuv/server/log.h"

namespace soupuv::server {

JobReaper::JobReaper(JobQueue& queue, const Config& config, Metrics& metrics)
    : queue_(queue), config_(config), metrics_(metrics) {}

JobReaper::~JobReaper() { stop(); }

void JobReaper::start() { thread_ = std::thread([this] { loop(); }); }

void JobReaper::stop() {
  {
    std::lock_guard lock(mu_);
    stopping_ = true;
  }
  cv_.notify_all();
  if (thread_.joinable()) thread_.join();
}

ReapResult JobReaper::reap_once() {
  ReapResult r = queue_.reap(config_.max_attempts);
  for (const auto& id : r.requeued) log::warn("lease expired; job queued again", {{"job", id}});
  for (const auto& id : r.failed) log::warn("lease expired on the last attempt; job failed", {{"job", id}});
  if (!r.requeued.empty() || !r.failed.empty())
    metrics_.leases_reaped(int64_t(r.requeued.size()), int64_t(r.failed.size()));
  return r;
}

void JobReaper::loop() {
  const auto period = std::chrono::milliseconds(int(std::max(0.2, config_.lease_seconds / 5.0) * 1000));
  std::unique_lock lock(mu_);
  while (!stopping_) {
    cv_.wait_for(lock, period, [&] { return stopping_; });
    if (stopping_) break;
    lock.unlock();
    try {
      reap_once();
    } catch (const std::exception& e) {
      log::warn("reaper round failed", {{"error", e.what()}});  // the database is away: next round
    }
    lock.lock();
  }
}

}  // namespace soupuv::server
