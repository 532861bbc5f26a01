// Prometheus text exposition of the server's counters: HTTP requests by code,
// jobs by state (from the store), queue depth, busy workers, stage duration
// histograms, worker outcomes, cache hits reported by diagnostics.
#pragma once

#include <atomic>
#include <map>
#include <mutex>
#include <string>
#include <vector>

namespace soupuv::server {

class Metrics {
 public:
  void http_request(int status);
  // Time inside the server for one request (headers parsed -> response
  // written), by route class: status, healthz, readyz, other. Compared with a
  // client's latency it separates the server's work from waiting for a CPU.
  void http_duration(const std::string& route, double seconds);
  void stage_seconds(const std::string& stage, double seconds);
  void job_finished(const std::string& state);
  void cache_hits(int64_t hits);
  void upload_bytes(int64_t bytes);
  // Shared queue (--database-url) only; rendered once shared_queue() is set.
  void shared_queue() { shared_queue_ = true; }
  void lease_lost();                                 // a heartbeat found a lease gone
  void leases_reaped(int64_t requeued, int64_t failed);  // by this node's reaper

  // `gauges` are point-in-time values the caller samples (queue depth, jobs by state).
  std::string render(const std::map<std::string, double>& gauges) const;

 private:
  static const std::vector<double>& buckets();
  static const std::vector<double>& http_buckets();
  struct Histogram {
    std::vector<uint64_t> counts;  // cumulative per bucket, filled at render
    std::vector<uint64_t> raw;
    double sum = 0;
    uint64_t count = 0;
  };
  mutable std::mutex mu_;
  std::atomic<bool> shared_queue_{false};
  uint64_t leases_lost_ = 0, reaped_requeued_ = 0, reaped_failed_ = 0;
  std::map<int, uint64_t> http_by_code_;
  std::map<std::string, Histogram> stages_;
  std::map<std::string, Histogram> http_durations_;
  std::map<std::string, uint64_t> finished_by_state_;
  uint64_t cache_hits_ = 0;
  uint64_t upload_bytes_ = 0;
};

}  // namespace soupuv::server
