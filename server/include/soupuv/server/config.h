// soupuv-server configuration: command-line flags override SOUPUV_* environment
// variables, which override the embedded defaults (one process, everything under
// ./soupuv-data, no other service).
//
// Inputs: argv and an environment lookup. Output: Config, or ConfigError with a
// one-line reason. Flag --name maps to env SOUPUV_NAME (dashes -> underscores).
#pragma once

#include <algorithm>
#include <cstdint>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace soupuv::server {

struct Config {
  std::string host = "127.0.0.1";
  int port = 8080;
  std::string data_dir = "./soupuv-data";
  int workers = 1;                      // concurrent worker processes
  int threads = 0;                      // total pipeline threads over all workers (0: cores)
  int queue_capacity = 50;              // queued (not running) jobs
  int64_t max_upload_bytes = 256ll << 20;
  int job_timeout_s = 600;              // wall clock per job attempt
  // Runs of one job before it fails for good when its worker crashes, is
  // killed from outside (OOM killer) or is lost with the server.
  int max_attempts = 3;
  int result_ttl_s = 86400;             // finished jobs and their files
  int64_t worker_memory_mb = 8192;      // RLIMIT_AS per worker
  int64_t worker_max_file_mb = 4096;    // RLIMIT_FSIZE per worker (largest file it may write)
  // Landlock for workers (sandbox.h): auto (when the kernel has it), landlock
  // (required: no start without it), off.
  std::string worker_sandbox = "auto";
  // Names of server environment variables passed to workers (which otherwise
  // get only PATH, HOME, TMPDIR, LANG, OMP_NUM_THREADS).
  std::vector<std::string> worker_env = {"ASAN_OPTIONS", "UBSAN_OPTIONS", "LSAN_OPTIONS"};
  std::string tokens_file;              // empty: no authentication (loopback only, see below)
  // Serve without tokens on a non-loopback --host. Off: such a start is
  // refused, so no shipped configuration is anonymous by accident.
  bool allow_anonymous = false;
  // A second listener serving only /metrics, without a token (for a
  // scraper on a private network). 0: none; /metrics is then on the main
  // port and needs a token when tokens are configured.
  std::string metrics_host = "127.0.0.1";
  int metrics_port = 0;
  int64_t cache_size_mb = 1024;         // budget of DATA/cache/, the workers' shared field cache (pruned by the sweeper)
  std::vector<std::string> cors_origins;  // exact origins allowed; empty: none
  std::string worker_bin;               // soupuv CLI; empty: next to the server
  std::string web_dir;                  // upload page; empty: next to the server
  int http_threads = 32;                // threads serving requests (uploads, downloads, polls)
  // Request heads are read by one epoll thread (connection_gate.h) within
  // these bounds before any HTTP thread sees them.
  int header_timeout_s = 10;            // first byte of a head to its end; then 408
  int max_header_bytes = 16384;         // then 431
  int max_header_lines = 100;           // then 431
  int64_t min_body_rate = 1024;         // bytes/s a request body must average after 10 s
  // Uploads in flight (body streaming + inspect) at once; more get 503 +
  // Retry-After before their body is read. 0: half the HTTP threads, so the
  // other half always answers polls and health checks without queueing.
  int max_uploads = 0;
  // Free space the data directory keeps: an upload that would leave less is
  // refused (503 + Retry-After) and /readyz reports not ready.
  int64_t min_free_mb = 512;
  bool validate_uploads = true;         // run `soupuv inspect` before queueing
  // Scale-out (job_queue.h): a postgresql:// URL puts jobs, the queue, inputs
  // and results in that database, shared by every process given the same
  // URL. Empty: the embedded SQLite file and data directory.
  std::string database_url;
  double lease_seconds = 30;            // a claimed job's lease; renewed 5 times per lease
  int poll_interval_ms = 1000;          // idle workers look at the shared queue this often (NOTIFY wakes them sooner)
  // Job-end callbacks (callbacks.h): the HMAC key (empty: callback_url is
  // refused), and whether loopback/private targets are allowed (tests, LANs).
  std::string callback_secret;
  bool callback_allow_private = false;
  std::string log_level = "info";

  int threads_per_job() const;
  int upload_slots() const { return max_uploads > 0 ? max_uploads : std::max(1, http_threads / 2); }
};

class ConfigError : public std::runtime_error {
  using std::runtime_error::runtime_error;
};

using EnvLookup = std::function<std::optional<std::string>(const std::string&)>;

// Throws ConfigError (also when --host is not loopback and neither
// --tokens-file nor --allow-anonymous is given). `--help` is not handled here.
Config parse_config(const std::vector<std::string>& args, const EnvLookup& env);
EnvLookup process_env();
// 127.0.0.0/8, ::1 or "localhost".
bool is_loopback_host(const std::string& host);
std::string help_text();

}  // namespace soupuv::server
