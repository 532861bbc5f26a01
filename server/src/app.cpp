#include "soupuv/server/app.h"

#include <sys/socket.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "soupuv/server/cache_prune.h"
#include "soupuv/server/log.h"
#include "soupuv/server/pg_job_store.h"
#include "soupuv/server/pg_schema.h"
#include "soupuv/server/problem.h"
#include "soupuv/server/sandbox.h"
#include "soupuv/server/storage.h"

namespace soupuv::server {
namespace fs = std::filesystem;
namespace {

std::string mime_for(const fs::path& p) {
  const std::string ext = p.extension().string();
  if (ext == ".html") return "text/html; charset=utf-8";
  if (ext == ".js" || ext == ".mjs") return "text/javascript; charset=utf-8";
  if (ext == ".css") return "text/css; charset=utf-8";
  if (ext == ".svg") return "image/svg+xml";
  if (ext == ".png") return "image/png";
  if (ext == ".json") return "application/json";
  if (ext == ".yaml") return "application/yaml";
  return "application/octet-stream";
}

// Reads the whole web directory once: requests are then looked up in a map,
// so no file path is ever built from a request.
std::map<std::string, WebAsset> load_web(const fs::path& dir) {
  std::map<std::string, WebAsset> out;
  if (!fs::is_directory(dir)) return out;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    if (!e.is_regular_file()) continue;
    std::string rel = fs::relative(e.path(), dir).generic_string();
    std::ifstream in(e.path(), std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    WebAsset a{mime_for(e.path()), std::move(bytes)};
    if (rel == "index.html") out["/"] = a;
    out["/assets/" + rel] = std::move(a);
  }
  return out;
}

}  // namespace

std::string executable_dir() {
  std::error_code ec;
  fs::path p = fs::read_symlink("/proc/self/exe", ec);
  return ec ? std::string(".") : p.parent_path().string();
}

std::string find_worker_binary(const std::string& configured) {
  if (!configured.empty()) return access(configured.c_str(), X_OK) == 0 ? fs::absolute(configured).string() : "";
  const fs::path here = executable_dir();
  for (const fs::path& p : {here / "soupuv", here / ".." / "core" / "apps" / "soupuv", here / ".." / "bin" / "soupuv"})
    if (access(p.c_str(), X_OK) == 0) return fs::weakly_canonical(p).string();
  return "";
}

App::App(Config config) {
  ctx_.config = std::move(config);
  const Config& c = ctx_.config;
  ctx_.data = std::make_unique<DataDir>(fs::absolute(c.data_dir));
  if (c.database_url.empty()) {
    ctx_.store = with_memory_snapshot(open_sqlite_job_store(ctx_.data->database().string()));
    ctx_.blobs = open_file_blob_store(*ctx_.data);
  } else {
    open_database();
  }
  if (!c.tokens_file.empty()) ctx_.tokens.set(TokenSet::load(c.tokens_file));
  if (c.worker_sandbox == "landlock" && landlock_abi() == 0)
    throw std::runtime_error("--worker-sandbox landlock: this kernel has no Landlock (Linux >= 5.13 with landlock "
                             "in the LSM list); use --worker-sandbox auto or off to run workers unconfined");
  if (!sandbox_active(c))
    log::warn("workers run without the Landlock sandbox: a hostile model's parser could read the server's files",
              {{"worker_sandbox", c.worker_sandbox}, {"landlock_abi", landlock_abi()}});
  ctx_.worker_bin = find_worker_binary(c.worker_bin);
  if (!c.worker_bin.empty() && ctx_.worker_bin.empty())
    throw std::runtime_error("--worker-bin " + c.worker_bin + " is not an executable file");
  if (!ctx_.worker_bin.empty()) ctx_.caps = probe_worker(ctx_.worker_bin);
  log::info("worker", {{"bin", ctx_.worker_bin}, {"flags", ctx_.caps.flags}, {"inspect", ctx_.caps.has_inspect}});

  fs::path web = c.web_dir.empty() ? fs::path(executable_dir()) / "web" : fs::path(c.web_dir);
  ctx_.web = load_web(web);
  if (ctx_.web.empty()) log::warn("no upload page assets", {{"web_dir", web.string()}});
  for (const fs::path& p : {web / "openapi.yaml", fs::path(executable_dir()) / "openapi.yaml"})
    if (fs::exists(p)) {
      std::ifstream in(p);
      ctx_.openapi_yaml.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
      break;
    }

  ctx_.scheduler = std::make_unique<Scheduler>(ctx_.config, ctx_.worker_bin, ctx_.caps, *ctx_.store,
                                               *ctx_.data, ctx_.metrics, *ctx_.blobs, ctx_.queue, ctx_.node_id);
  // Job-end callbacks: the finished job's JSON to its params.callback_url.
  if (!c.callback_secret.empty()) {
    ctx_.callbacks = std::make_unique<CallbackSender>(c.callback_secret, c.callback_allow_private);
    ctx_.scheduler->set_on_finish([this](const std::string& id) {
      auto job = ctx_.store->get(id);
      if (job && job->params.contains("callback_url") && job->params["callback_url"].is_string())
        ctx_.callbacks->post(job->params["callback_url"].get<std::string>(), to_json(*job));
    });
  }
  // Hardening: read/write timeouts for bodies and answers (heads are the
  // connection gate's, below), a body cap in httplib itself as a second line
  // behind the Content-Length guard.
  http_.set_payload_max_length(size_t(c.max_upload_bytes));
  http_.set_read_timeout(30, 0);
  http_.set_write_timeout(30, 0);
  // Keep-alive: up to 100 requests per connection, 5 s idle. Safe because
  // every refusal that may leave a body unread closes its connection
  // (HttpServer, close_connection_after in routes.cpp). A proxy in front must
  // drop idle upstream connections sooner (deploy/nginx: keepalive_timeout 4s)..
  http_.set_keep_alive_timeout(5);
  http_.set_keep_alive_max_count(100);
  // Heads are read by the connection gate (bounded), bodies on the HTTP threads.
  HttpServer::Limits limits;
  limits.worker_threads = size_t(c.http_threads);
  limits.gate.head_timeout = std::chrono::seconds(c.header_timeout_s);
  limits.gate.idle_timeout = std::chrono::seconds(5);  // = the keep-alive timeout above
  limits.gate.max_head_bytes = size_t(c.max_header_bytes);
  limits.gate.max_head_lines = size_t(c.max_header_lines);
  limits.min_body_rate = double(c.min_body_rate);
  http_.set_limits(limits);
  // httplib's default also sets SO_REUSEPORT, which lets a second server
  // silently share the port with a live one; keep only SO_REUSEADDR.
  http_.set_socket_options([](socket_t sock) {
    int yes = 1;
    setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
  });
  // Headers and body go out in separate writes: without NODELAY, Nagle and the
  // client's delayed ACK add ~40 ms to every small response.
  http_.set_tcp_nodelay(true);
  register_routes(http_, ctx_);
}

App::~App() { stop(); }

void App::open_database() {
  const Config& c = ctx_.config;
  // A malformed URL is the operator's typo, not an outage: refuse it now
  // instead of waiting a minute for a database that cannot exist.
  char* parse_error = nullptr;
  PQconninfoOption* parsed = PQconninfoParse(c.database_url.c_str(), &parse_error);
  if (!parsed) {
    std::string why = parse_error ? parse_error : "out of memory";
    PQfreemem(parse_error);
    while (!why.empty() && why.back() == '\n') why.pop_back();
    throw std::runtime_error("--database-url " + redact_database_url(c.database_url) + ": " + why);
  }
  PQconninfoFree(parsed);
  char host[256] = {};
  gethostname(host, sizeof host - 1);
  std::string h;
  for (char ch : std::string(host).substr(0, 64))
    h += (std::isalnum(static_cast<unsigned char>(ch)) || ch == '-' || ch == '.') ? ch : '_';
  // Unique per process start (a restarted node must not pass for the old
  // one, whose leases are left to expire): host, pid and a random tag.
  ctx_.node_id = (h.empty() ? "node" : h) + "-" + std::to_string(getpid()) + "-" + new_job_id().substr(1, 6);
  // Workers write, HTTP threads read: enough connections that neither waits
  // long for the other, few enough that 10 nodes fit PostgreSQL's default
  // max_connections of 100 (each node: workers + 6, 2 for heartbeats and
  // progress, 3 for blobs, 1 listener).
  ctx_.pool = std::make_unique<PgPool>(c.database_url, c.workers + 6);
  ctx_.advisory_pool = std::make_unique<PgPool>(c.database_url, 2, kAdvisoryWrites);
  ctx_.blob_pool = std::make_unique<PgPool>(c.database_url, 3);
  // Nodes may start before the database accepts connections (compose,
  // Kubernetes): wait up to a minute for it, then give up with the reason.
  for (int i = 0;; ++i) {
    try {
      auto conn = ctx_.pool->take();
      int applied = migrate_pg_schema(*conn);
      log::info("database", {{"url", redact_database_url(c.database_url)}, {"schema_version", pg_schema_version()},
                             {"migrations_applied", applied}, {"node", ctx_.node_id}});
      break;
    } catch (const StorageUnavailable& e) {
      if (i >= 60) throw std::runtime_error(std::string("cannot reach the database: ") + e.what());
      if (i % 10 == 0) log::warn("waiting for the database", {{"error", e.what()}});
      std::this_thread::sleep_for(std::chrono::seconds(1));
    }
  }
  auto pg = std::make_unique<PgJobStore>(*ctx_.pool, ctx_.advisory_pool.get());
  ctx_.queue = pg.get();
  ctx_.store = std::move(pg);
  ctx_.blobs = open_pg_blob_store(*ctx_.blob_pool);
  ctx_.metrics.shared_queue();
}

bool App::bind() {
  const Config& c = ctx_.config;
  if (c.metrics_port > 0) {
    metrics_http_ = std::make_unique<httplib::Server>();
    metrics_http_->Get("/metrics", [this](const httplib::Request&, httplib::Response& res) {
      res.set_content(render_metrics(ctx_), "text/plain; version=0.0.4");
    });
    metrics_http_->set_error_handler([](const httplib::Request&, httplib::Response& res) {
      set_problem(res, res.status == 0 ? 404 : res.status, "not-found", "this listener serves /metrics only");
    });
    metrics_http_->new_task_queue = [] { return new httplib::ThreadPool(2); };
    if (!metrics_http_->bind_to_port(c.metrics_host, c.metrics_port)) {
      log::error("cannot bind the metrics listener", {{"host", c.metrics_host}, {"port", c.metrics_port}});
      return false;
    }
  }
  if (c.port == 0) {
    port_ = http_.bind_to_any_port(c.host);
    if (port_ <= 0) return false;
  } else {
    if (!http_.bind_to_port(c.host, c.port)) return false;
    port_ = c.port;
  }
  if (!http_.set_listen_backlog(SOMAXCONN)) log::warn("could not raise the listen backlog", {{"errno", errno}});
  return true;
}

void App::serve() {
  size_t recovered = ctx_.scheduler->recover();
  ctx_.scheduler->start();
  if (ctx_.queue) {
    listener_ = std::make_unique<PgListener>(ctx_.config.database_url, [this](const std::string& channel,
                                                                              const std::string& payload) {
      if (channel == kCancelChannel) ctx_.scheduler->cancel_local(payload);
      else ctx_.scheduler->wake();
    });
    listener_->start();
    reaper_ = std::make_unique<JobReaper>(*ctx_.queue, ctx_.config, ctx_.metrics);
    reaper_->start();
  }
  sweeper_ = std::thread([this] { sweep_loop(); });
  if (metrics_http_) metrics_thread_ = std::thread([this] { metrics_http_->listen_after_bind(); });
  log::info("listening", {{"host", ctx_.config.host}, {"port", port_}, {"data_dir", ctx_.data->root().string()},
                          {"workers", ctx_.config.workers}, {"queue_capacity", ctx_.config.queue_capacity},
                          {"threads_per_job", ctx_.config.threads_per_job()}, {"recovered_jobs", recovered},
                          {"auth", ctx_.tokens.enabled()}, {"metrics_port", ctx_.config.metrics_port},
                          {"worker_sandbox", sandbox_active(ctx_.config) ? "landlock" : "off"},
                          {"landlock_abi", landlock_abi()}});
  http_.listen_after_bind();
}

void App::stop() {
  {
    std::lock_guard lock(sweep_mu_);
    if (stopping_) return;
    stopping_ = true;
  }
  sweep_cv_.notify_all();
  http_.stop();
  http_.close_connections();
  if (metrics_http_) metrics_http_->stop();
  if (metrics_thread_.joinable()) metrics_thread_.join();
  if (ctx_.scheduler) ctx_.scheduler->stop();
  if (reaper_) reaper_->stop();
  if (listener_) listener_->stop();
  if (sweeper_.joinable()) sweeper_.join();
  log::info("stopped");
}

bool App::reload_tokens() {
  const std::string& path = ctx_.config.tokens_file;
  if (path.empty()) {
    log::info("SIGHUP: no --tokens-file to reload");
    return false;
  }
  try {
    TokenSet next = TokenSet::load(path);
    const size_t n = next.size();
    ctx_.tokens.set(std::move(next));
    log::info("tokens reloaded", {{"tokens", n}});
    return true;
  } catch (const std::exception& e) {
    log::error("tokens file not reloaded; the previous tokens stay in force", {{"error", e.what()}});
    return false;
  }
}

void App::sweep_loop() {
  const auto period = std::chrono::seconds(std::clamp(ctx_.config.result_ttl_s / 4, 1, 60));
  std::unique_lock lock(sweep_mu_);
  while (!stopping_) {
    sweep_cv_.wait_for(lock, period, [&] { return stopping_; });
    if (stopping_) break;
    lock.unlock();
    try {
      if (ctx_.queue) {
        // The database's clock decides and deletes rows and blobs together;
        // any node may do it, each row once (SKIP LOCKED).
        for (const auto& id : ctx_.queue->expire(ctx_.config.result_ttl_s)) log::info("job expired", {{"job", id}});
        // Scratch directories of attempts a killed process left here.
        std::error_code ec;
        for (const auto& e : fs::directory_iterator(ctx_.data->root() / "jobs", ec)) {
          auto age = fs::file_time_type::clock::now() - fs::last_write_time(e.path(), ec);
          if (!ec && age > std::chrono::seconds(ctx_.config.job_timeout_s + 3600)) fs::remove_all(e.path(), ec);
        }
      } else {
        for (const auto& id : ctx_.store->finished_before(now_seconds() - ctx_.config.result_ttl_s)) {
          if (!is_valid_job_id(id)) continue;
          std::error_code ec;
          fs::remove_all(ctx_.data->job(id), ec);
          ctx_.store->remove(id);
          log::info("job expired", {{"job", id}});
        }
      }
      auto pruned = prune_cache(ctx_.data->cache(), ctx_.config.cache_size_mb << 20);
      if (pruned.files_removed > 0)
        log::info("field cache pruned", {{"files", pruned.files_removed}, {"bytes_before", pruned.bytes_before},
                                         {"bytes_after", pruned.bytes_after}});
      // Half-written cache entries and temp files of killed workers; older
      // than any attempt may run, so no live write is touched.
      const auto temp_age = std::chrono::seconds(std::max(3600, ctx_.config.job_timeout_s + 60));
      if (int n = sweep_stale_temp_files(ctx_.data->root(), temp_age); n > 0)
        log::info("stale temp files removed", {{"files", n}});
      // Uploads interrupted mid-stream (client gone, server killed).
      std::error_code ec;
      for (const auto& e : fs::directory_iterator(ctx_.data->uploads_tmp(), ec)) {
        auto age = fs::file_time_type::clock::now() - fs::last_write_time(e.path(), ec);
        if (!ec && age > std::chrono::hours(1)) fs::remove_all(e.path(), ec);
      }
    } catch (const std::exception& e) {
      log::error("sweep failed", {{"error", e.what()}});
    }
    lock.lock();
  }
}

}  // namespace soupuv::server
