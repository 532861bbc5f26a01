// Flag/env parsing for Config. One table lists every option once, so a flag,
// its environment variable and its help line cannot drift apart.
#include "soupuv/server/config.h"

#include <arpa/inet.h>

#include <algorithm>
#include <charconv>
#include <cstdlib>
#include <thread>

namespace soupuv::server {
namespace {

struct Option {
  const char* name;  // flag without dashes; env is SOUPUV_ + upper(name)
  const char* help;
  std::function<void(Config&, const std::string&)> set;
};

int64_t parse_int(const std::string& name, const std::string& v, int64_t lo, int64_t hi) {
  int64_t out = 0;
  auto [p, ec] = std::from_chars(v.data(), v.data() + v.size(), out);
  if (ec != std::errc() || p != v.data() + v.size() || out < lo || out > hi)
    throw ConfigError("--" + name + ": expected an integer in [" + std::to_string(lo) + ", " +
                      std::to_string(hi) + "], got '" + v + "'");
  return out;
}

bool parse_bool(const std::string& name, const std::string& v) {
  if (v == "1" || v == "true" || v == "yes" || v == "on") return true;
  if (v == "0" || v == "false" || v == "no" || v == "off") return false;
  throw ConfigError("--" + name + ": expected true or false, got '" + v + "'");
}

std::vector<std::string> split_list(const std::string& v) {
  std::vector<std::string> out;
  size_t start = 0;
  while (start <= v.size()) {
    size_t end = v.find(',', start);
    if (end == std::string::npos) end = v.size();
    std::string item = v.substr(start, end - start);
    if (!item.empty()) out.push_back(item);
    start = end + 1;
  }
  return out;
}

const std::vector<Option>& options() {
  static const std::vector<Option> table = {
      {"host", "listen address (default 127.0.0.1)", [](Config& c, const std::string& v) { c.host = v; }},
      {"port", "listen port (default 8080; 0 picks a free port)",
       [](Config& c, const std::string& v) { c.port = int(parse_int("port", v, 0, 65535)); }},
      {"data-dir", "jobs database, uploads and results (default ./soupuv-data)",
       [](Config& c, const std::string& v) { c.data_dir = v; }},
      {"workers", "concurrent worker processes (default 1)",
       [](Config& c, const std::string& v) { c.workers = int(parse_int("workers", v, 1, 256)); }},
      {"threads", "total pipeline threads shared by all workers (default: CPU cores)",
       [](Config& c, const std::string& v) { c.threads = int(parse_int("threads", v, 0, 4096)); }},
      {"queue-capacity", "jobs waiting for a worker before 429 (default 50)",
       [](Config& c, const std::string& v) { c.queue_capacity = int(parse_int("queue-capacity", v, 1, 1000000)); }},
      {"max-upload-bytes", "largest accepted request body (default 268435456)",
       [](Config& c, const std::string& v) { c.max_upload_bytes = parse_int("max-upload-bytes", v, 1, int64_t(1) << 40); }},
      {"job-timeout", "wall-clock seconds per job attempt (default 600)",
       [](Config& c, const std::string& v) { c.job_timeout_s = int(parse_int("job-timeout", v, 1, 7 * 86400)); }},
      {"max-attempts", "runs of a job whose worker crashed, was killed or was lost with the server, before it fails (default 3)",
       [](Config& c, const std::string& v) { c.max_attempts = int(parse_int("max-attempts", v, 1, 100)); }},
      {"result-ttl", "seconds finished jobs and their files are kept (default 86400)",
       [](Config& c, const std::string& v) { c.result_ttl_s = int(parse_int("result-ttl", v, 1, 365 * 86400)); }},
      {"worker-memory-mb", "address-space limit of each worker process (default 8192)",
       [](Config& c, const std::string& v) { c.worker_memory_mb = parse_int("worker-memory-mb", v, 64, 1 << 22); }},
      {"worker-max-file-mb", "largest file a worker may write, RLIMIT_FSIZE (default 4096)",
       [](Config& c, const std::string& v) { c.worker_max_file_mb = parse_int("worker-max-file-mb", v, 1, 1 << 22); }},
      {"worker-sandbox", "auto, landlock or off: confine workers with Landlock (auto: when the kernel has it)",
       [](Config& c, const std::string& v) {
         if (v != "auto" && v != "landlock" && v != "off")
           throw ConfigError("--worker-sandbox: expected auto, landlock or off, got '" + v + "'");
         c.worker_sandbox = v;
       }},
      {"worker-env", "comma-separated names of environment variables passed to workers "
                     "(default ASAN_OPTIONS,UBSAN_OPTIONS,LSAN_OPTIONS)",
       [](Config& c, const std::string& v) { c.worker_env = split_list(v); }},
      {"tokens-file", "bearer tokens, one `TOKEN` or `TENANT TOKEN` a line, >= 32 bytes each; reloaded on SIGHUP "
                      "(default: none, allowed only on a loopback --host)",
       [](Config& c, const std::string& v) { c.tokens_file = v; }},
      {"allow-anonymous", "serve a non-loopback --host without --tokens-file (default false: refused)",
       [](Config& c, const std::string& v) { c.allow_anonymous = parse_bool("allow-anonymous", v); }},
      {"metrics-host", "address of the --metrics-port listener (default 127.0.0.1)",
       [](Config& c, const std::string& v) { c.metrics_host = v; }},
      {"metrics-port", "own port serving only /metrics, without a token (default 0: /metrics on the main port)",
       [](Config& c, const std::string& v) { c.metrics_port = int(parse_int("metrics-port", v, 0, 65535)); }},
      {"cache-size-mb", "field cache size on disk, shared by workers; the server prunes the oldest entries (default 1024)",
       [](Config& c, const std::string& v) { c.cache_size_mb = parse_int("cache-size-mb", v, 0, 1 << 24); }},
      {"cors-origins", "comma-separated origins allowed by CORS (default none)",
       [](Config& c, const std::string& v) { c.cors_origins = split_list(v); }},
      {"worker-bin", "path of the soupuv CLI used as worker (default: next to soupuv-server)",
       [](Config& c, const std::string& v) { c.worker_bin = v; }},
      {"web-dir", "upload page assets (default: web/ next to soupuv-server)",
       [](Config& c, const std::string& v) { c.web_dir = v; }},
      {"http-threads", "HTTP I/O threads (default 32)",
       [](Config& c, const std::string& v) { c.http_threads = int(parse_int("http-threads", v, 2, 1024)); }},
      {"header-timeout", "seconds a client has to send a whole request head, then 408 (default 10)",
       [](Config& c, const std::string& v) { c.header_timeout_s = int(parse_int("header-timeout", v, 1, 600)); }},
      {"max-header-bytes", "largest request head, then 431 (default 16384)",
       [](Config& c, const std::string& v) { c.max_header_bytes = int(parse_int("max-header-bytes", v, 1024, 1 << 20)); }},
      {"max-header-lines", "most header lines in a request, then 431 (default 100)",
       [](Config& c, const std::string& v) { c.max_header_lines = int(parse_int("max-header-lines", v, 8, 10000)); }},
      {"min-body-rate", "bytes/s a request body must average once it has taken 10 s (default 1024)",
       [](Config& c, const std::string& v) { c.min_body_rate = parse_int("min-body-rate", v, 1, int64_t(1) << 30); }},
      {"max-uploads", "uploads in flight at once, beyond: 503 + Retry-After (default: half the HTTP threads)",
       [](Config& c, const std::string& v) { c.max_uploads = int(parse_int("max-uploads", v, 1, 1024)); }},
      {"min-free-mb", "free space the data directory keeps; below it uploads get 503 and /readyz fails (default 512)",
       [](Config& c, const std::string& v) { c.min_free_mb = parse_int("min-free-mb", v, 0, int64_t(1) << 40); }},
      {"callback-secret", "HMAC-SHA256 key signing job-end callbacks (Soupuv-Signature); without it callback_url is refused",
       [](Config& c, const std::string& v) { c.callback_secret = v; }},
      {"callback-allow-private", "let callback_url reach loopback, private and link-local addresses (default false)",
       [](Config& c, const std::string& v) { c.callback_allow_private = parse_bool("callback-allow-private", v); }},
      {"validate-uploads", "check each upload with `soupuv inspect` before queueing (default true)",
       [](Config& c, const std::string& v) { c.validate_uploads = parse_bool("validate-uploads", v); }},
      {"database-url", "postgresql://USER:PASSWORD@HOST:PORT/DB: jobs, queue, inputs and results in PostgreSQL, "
                       "shared by every server with the same URL (default none: SQLite and files in --data-dir)",
       [](Config& c, const std::string& v) {
         if (!v.empty() && v.rfind("postgresql://", 0) != 0 && v.rfind("postgres://", 0) != 0)
           throw ConfigError("--database-url must start with postgresql:// (or be empty for the embedded store)");
         c.database_url = v;
       }},
      {"lease-seconds", "with --database-url: seconds a worker holds a claimed job without a heartbeat before "
                        "another node may run it (default 30)",
       [](Config& c, const std::string& v) { c.lease_seconds = double(parse_int("lease-seconds", v, 1, 3600)); }},
      {"poll-interval-ms", "with --database-url: how often idle workers look at the queue besides notifications "
                           "(default 1000)",
       [](Config& c, const std::string& v) { c.poll_interval_ms = int(parse_int("poll-interval-ms", v, 10, 60000)); }},
      {"log-level", "trace, debug, info, warn, error (default info)",
       [](Config& c, const std::string& v) {
         static const char* levels[] = {"trace", "debug", "info", "warn", "error", "off"};
         if (std::find(std::begin(levels), std::end(levels), v) == std::end(levels))
           throw ConfigError("--log-level: unknown level '" + v + "'");
         c.log_level = v;
       }},
  };
  return table;
}

std::string env_name(const std::string& flag) {
  std::string out = "SOUPUV_";
  for (char ch : flag) out += ch == '-' ? '_' : char(std::toupper(static_cast<unsigned char>(ch)));
  return out;
}

const Option* find_option(const std::string& name) {
  for (const auto& o : options())
    if (name == o.name) return &o;
  return nullptr;
}

}  // namespace

int Config::threads_per_job() const {
  int total = threads > 0 ? threads : int(std::max(1u, std::thread::hardware_concurrency()));
  return std::max(1, total / workers);
}

Config parse_config(const std::vector<std::string>& args, const EnvLookup& env) {
  Config c;
  for (const auto& o : options())
    if (auto v = env(env_name(o.name))) o.set(c, *v);
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a.rfind("--", 0) != 0) throw ConfigError("unexpected argument '" + a + "'");
    std::string name = a.substr(2), value;
    size_t eq = name.find('=');
    if (eq != std::string::npos) {
      value = name.substr(eq + 1);
      name = name.substr(0, eq);
    } else {
      if (i + 1 >= args.size()) throw ConfigError("--" + name + " needs a value");
      value = args[++i];
    }
    const Option* o = find_option(name);
    if (!o) throw ConfigError("unknown flag --" + name + " (see --help)");
    o->set(c, value);
  }
  if (c.tokens_file.empty() && !c.allow_anonymous && !is_loopback_host(c.host))
    throw ConfigError("--host " + c.host +
                      " is reachable from other machines and no --tokens-file is given: anyone could submit, read "
                      "and delete jobs. Give --tokens-file FILE, or --allow-anonymous true to serve without "
                      "authentication on purpose");
  return c;
}

bool is_loopback_host(const std::string& host) {
  if (host == "localhost" || host == "::1") return true;
  in_addr a{};
  return inet_pton(AF_INET, host.c_str(), &a) == 1 && (ntohl(a.s_addr) >> 24) == 127;
}

EnvLookup process_env() {
  return [](const std::string& name) -> std::optional<std::string> {
    const char* v = std::getenv(name.c_str());
    if (!v) return std::nullopt;
    return std::string(v);
  };
}

std::string help_text() {
  std::string out =
      "usage: soupuv-server [--flag value | --flag=value]...\n"
      "Serves the soupuv REST API (/v1), the upload page (/), /healthz, /readyz, /metrics.\n"
      "Every flag can also be given as an environment variable SOUPUV_<FLAG>.\n\n";
  for (const auto& o : options()) {
    std::string flag = std::string("  --") + o.name;
    flag.resize(std::max<size_t>(flag.size() + 1, 22), ' ');
    out += flag + o.help + "  [" + env_name(o.name) + "]\n";
  }
  return out;
}

}  // namespace soupuv::server
