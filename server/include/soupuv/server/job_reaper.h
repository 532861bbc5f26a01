// The shared queue's reaper (--database-url): every node runs one. It
// re-queues jobs whose lease expired (the node running them died, was
// paused, or lost the database) while attempts remain, and fails the others
// with code `lost`. JobQueue::reap is safe on every node at once, so there is
// no leader to elect. Period: a fifth of the lease, so a dead node's jobs
// are queued again within lease + lease/5.
#pragma once

#include <condition_variable>
#include <mutex>
#include <thread>

#include "soupuv/server/config.h"
#include "soupuv/server/job_queue.h"
#include "soupuv/server/metrics.h"

namespace soupuv::server {

class JobReaper {
 public:
  JobReaper(JobQueue& queue, const Config& config, Metrics& metrics);
  ~JobReaper();  // stops
  void start();
  void stop();
  ReapResult reap_once();  // one round (tests)

 private:
  void loop();
  JobQueue& queue_;
  const Config& config_;
  Metrics& metrics_;
  std::mutex mu_;
  std::condition_variable cv_;
  bool stopping_ = false;
  std::thread thread_;
};

}  // namespace soupuv::server
