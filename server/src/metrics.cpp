#include "soupuv/server/metrics.h"

#include <cstdio>
#include <cstdlib>
#include <sstream>

namespace soupuv::server {

const std::vector<double>& Metrics::buckets() {
  static const std::vector<double> b = {0.01, 0.05, 0.1, 0.5, 1, 2.5, 5, 10, 30, 60, 120, 300, 600};
  return b;
}

void Metrics::http_request(int status) {
  std::lock_guard lock(mu_);
  ++http_by_code_[status];
}

const std::vector<double>& Metrics::http_buckets() {
  static const std::vector<double> b = {0.0005, 0.001, 0.0025, 0.005, 0.01, 0.025, 0.05, 0.1, 0.5, 1, 5, 30};
  return b;
}

namespace {

// Full precision: Prometheus parses Go floats; six digits would round sums
// and counters past a million.
std::string num(double v) {
  char buf[32];
  for (int precision = 15; precision <= 17; ++precision) {  // the shortest that reads back the same
    std::snprintf(buf, sizeof buf, "%.*g", precision, v);
    if (std::strtod(buf, nullptr) == v) break;
  }
  return buf;
}

// Label values escaped as the text format requires (backslash, quote, newline).
std::string label(const std::string& v) {
  std::string out;
  for (char c : v) {
    if (c == '\\' || c == '"') out += '\\';
    if (c == '\n') {
      out += "\\n";
      continue;
    }
    out += c;
  }
  return out;
}

// One line of HELP for each gauge the server samples (render's `gauges`).
const char* gauge_help(const std::string& name) {
  if (name == "queue_depth") return "Jobs waiting for a worker (with --database-url: across the service).";
  if (name == "queue_capacity") return "Jobs that may wait before submissions get 429.";
  if (name == "workers_busy") return "Worker processes running a job.";
  if (name == "workers") return "Configured worker processes.";
  return "Sampled by the server.";
}

template <typename H>
void observe(H& h, const std::vector<double>& bounds, double seconds) {
  if (h.raw.empty()) h.raw.assign(bounds.size(), 0);
  for (size_t i = 0; i < bounds.size(); ++i)
    if (seconds <= bounds[i]) {
      ++h.raw[i];
      break;
    }
  h.sum += seconds;
  ++h.count;
}

// Prometheus histogram lines (cumulative buckets, +Inf, sum, count).
template <typename H>
void render_histogram(std::ostringstream& o, const std::string& name, const std::string& key,
                      const std::string& value, const H& h, const std::vector<double>& bounds) {
  uint64_t cum = 0;
  const std::string lv = label(value);
  for (size_t i = 0; i < bounds.size(); ++i) {
    cum += h.raw[i];
    o << name << "_bucket{" << key << "=\"" << lv << "\",le=\"" << num(bounds[i]) << "\"} " << cum << "\n";
  }
  o << name << "_bucket{" << key << "=\"" << lv << "\",le=\"+Inf\"} " << h.count << "\n";
  o << name << "_sum{" << key << "=\"" << lv << "\"} " << num(h.sum) << "\n";
  o << name << "_count{" << key << "=\"" << lv << "\"} " << h.count << "\n";
}
}  // namespace

void Metrics::stage_seconds(const std::string& stage, double seconds) {
  std::lock_guard lock(mu_);
  observe(stages_[stage], buckets(), seconds);
}

void Metrics::http_duration(const std::string& route, double seconds) {
  std::lock_guard lock(mu_);
  observe(http_durations_[route], http_buckets(), seconds);
}

void Metrics::job_finished(const std::string& state) {
  std::lock_guard lock(mu_);
  ++finished_by_state_[state];
}

void Metrics::cache_hits(int64_t hits) {
  std::lock_guard lock(mu_);
  cache_hits_ += uint64_t(hits);
}

void Metrics::lease_lost() {
  std::lock_guard lock(mu_);
  ++leases_lost_;
}

void Metrics::leases_reaped(int64_t requeued, int64_t failed) {
  std::lock_guard lock(mu_);
  reaped_requeued_ += uint64_t(requeued);
  reaped_failed_ += uint64_t(failed);
}

void Metrics::upload_bytes(int64_t bytes) {
  std::lock_guard lock(mu_);
  upload_bytes_ += uint64_t(bytes);
}

std::string Metrics::render(const std::map<std::string, double>& gauges) const {
  std::ostringstream o;
  std::lock_guard lock(mu_);
  o << "# HELP soupuv_http_requests_total HTTP responses by status code.\n"
       "# TYPE soupuv_http_requests_total counter\n";
  for (const auto& [code, n] : http_by_code_)
    o << "soupuv_http_requests_total{code=\"" << code << "\"} " << n << "\n";
  o << "# HELP soupuv_build_info The server's version (value always 1).\n# TYPE soupuv_build_info gauge\n"
       "soupuv_build_info{version=\"" << label(SOUPUV_VERSION) << "\"} 1\n";
  o << "# HELP soupuv_jobs Jobs in the store by state.\n# TYPE soupuv_jobs gauge\n";
  for (const auto& [name, v] : gauges)
    if (name.rfind("jobs:", 0) == 0) o << "soupuv_jobs{state=\"" << label(name.substr(5)) << "\"} " << num(v) << "\n";
  for (const auto& [name, v] : gauges)
    if (name.rfind("jobs:", 0) != 0)
      o << "# HELP soupuv_" << name << " " << gauge_help(name) << "\n# TYPE soupuv_" << name << " gauge\nsoupuv_"
        << name << " " << num(v) << "\n";
  o << "# HELP soupuv_jobs_finished_total Jobs finished by this process, by final state.\n"
       "# TYPE soupuv_jobs_finished_total counter\n";
  for (const auto& [state, n] : finished_by_state_)
    o << "soupuv_jobs_finished_total{state=\"" << label(state) << "\"} " << n << "\n";
  o << "# HELP soupuv_stage_duration_seconds Pipeline stage durations reported by workers.\n"
       "# TYPE soupuv_stage_duration_seconds histogram\n";
  for (const auto& [stage, h] : stages_)
    render_histogram(o, "soupuv_stage_duration_seconds", "stage", stage, h, buckets());
  o << "# HELP soupuv_http_request_duration_seconds Time inside the server per request (headers read to response written).\n"
       "# TYPE soupuv_http_request_duration_seconds histogram\n";
  for (const auto& [route, h] : http_durations_)
    render_histogram(o, "soupuv_http_request_duration_seconds", "route", route, h, http_buckets());
  o << "# HELP soupuv_cache_hits_total Field-cache hits reported in job diagnostics.\n"
       "# TYPE soupuv_cache_hits_total counter\nsoupuv_cache_hits_total " << cache_hits_ << "\n";
  o << "# HELP soupuv_upload_bytes_total Bytes of accepted uploads.\n"
       "# TYPE soupuv_upload_bytes_total counter\nsoupuv_upload_bytes_total " << upload_bytes_ << "\n";
  if (shared_queue_) {
    o << "# HELP soupuv_leases_lost_total Jobs this node stopped because its lease was gone (another node took over).\n"
         "# TYPE soupuv_leases_lost_total counter\nsoupuv_leases_lost_total " << leases_lost_ << "\n";
    o << "# HELP soupuv_leases_reaped_total Expired leases this node's reaper handled, by outcome.\n"
         "# TYPE soupuv_leases_reaped_total counter\n"
         "soupuv_leases_reaped_total{outcome=\"requeued\"} " << reaped_requeued_ << "\n"
         "soupuv_leases_reaped_total{outcome=\"failed\"} " << reaped_failed_ << "\n";
  }
  return o.str();
}

}  // namespace soupuv::server
