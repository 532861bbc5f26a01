// LISTEN on the queue's channels (pg_job_store.h) with a connection of its
// own, in a thread: a NOTIFY wakes idle workers at once and carries cancels
// to the node running the job. Notifications are an optimisation only:
// workers also poll the queue (--poll-interval) and heartbeats carry cancel
// flags, so a notification lost while the connection was down (PostgreSQL
// restarting) delays work by at most one poll, never loses it.
#pragma once

#include <atomic>
#include <functional>
#include <string>
#include <thread>

namespace soupuv::server {

class PgListener {
 public:
  using Handler = std::function<void(const std::string& channel, const std::string& payload)>;
  PgListener(std::string url, Handler handler);
  ~PgListener();  // stops and joins
  void start();
  void stop();
  bool connected() const { return connected_; }

 private:
  void loop();
  std::string url_;
  Handler handler_;
  std::atomic<bool> stopping_{false}, connected_{false};
  std::thread thread_;
};

}  // namespace soupuv::server
