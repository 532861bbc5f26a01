// The server process: wires config, data directory, job store, scheduler,
// HTTP server (routes.cpp) and the TTL sweeper together.
#pragma once

#include <atomic>
#include <condition_variable>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include <httplib.h>

#include "soupuv/server/auth.h"
#include "soupuv/server/blob_store.h"
#include "soupuv/server/callbacks.h"
#include "soupuv/server/config.h"
#include "soupuv/server/files.h"
#include "soupuv/server/http_server.h"
#include "soupuv/server/job_queue.h"
#include "soupuv/server/job_reaper.h"
#include "soupuv/server/job_store.h"
#include "soupuv/server/metrics.h"
#include "soupuv/server/params.h"
#include "soupuv/server/pg_connection.h"
#include "soupuv/server/pg_listener.h"
#include "soupuv/server/scheduler.h"

namespace soupuv::server {

struct WebAsset {
  std::string content_type;
  std::string bytes;
};

// Everything a route handler may touch.
struct ServerContext {
  Config config;
  std::unique_ptr<DataDir> data;
  // --database-url: connections of the job store (status reads, worker
  // writes) and of the blob store (uploads, downloads) apart, so a large
  // transfer never makes a status poll wait for a connection. Declared before
  // the stores, destroyed after them.
  std::unique_ptr<PgPool> pool, advisory_pool, blob_pool;
  std::unique_ptr<JobStore> store;
  JobQueue* queue = nullptr;  // the store's shared queue; nullptr: embedded
  std::unique_ptr<BlobStore> blobs;  // inputs and results
  std::string node_id;  // this process in lease owners
  Metrics metrics;
  TokenRegistry tokens;  // empty set: no authentication (loopback or --allow-anonymous)
  std::string worker_bin;  // empty: none found
  WorkerCapabilities caps;
  std::unique_ptr<Scheduler> scheduler;
  std::unique_ptr<CallbackSender> callbacks;  // set when --callback-secret is
  std::map<std::string, WebAsset> web;  // URL path -> asset, loaded at start
  std::string openapi_yaml;
  std::atomic<int> validations_running{0};
  std::atomic<int> uploads_in_flight{0};
};

class App {
 public:
  explicit App(Config config);  // throws std::runtime_error on bad setup
  ~App();
  // Binds (port 0 picks one) and serves until stop(). Returns false if bind failed.
  bool bind();
  int port() const { return port_; }
  void serve();
  void stop();
  // Re-reads --tokens-file (SIGHUP). A file that no longer loads keeps the
  // tokens in force (never falls open) and is logged; false then.
  bool reload_tokens();

 private:
  void sweep_loop();
  void open_database();  // --database-url: pools, migrations, stores

  ServerContext ctx_;
  HttpServer http_;
  int port_ = 0;
  // --metrics-port: /metrics alone, no token (nullptr when not configured).
  std::unique_ptr<httplib::Server> metrics_http_;
  std::thread metrics_thread_;
  std::thread sweeper_;
  std::unique_ptr<PgListener> listener_;  // --database-url
  std::unique_ptr<JobReaper> reaper_;     // --database-url
  std::mutex sweep_mu_;
  std::condition_variable sweep_cv_;
  bool stopping_ = false;
};

// Prometheus text for /metrics (routes.cpp), on the main port or --metrics-port.
std::string render_metrics(ServerContext& ctx);

// Registers every route (routes.cpp). The table of (method, OpenAPI path) is
// what the contract test compares with proto/openapi.yaml.
void register_routes(httplib::Server& http, ServerContext& ctx);
struct RouteInfo {
  std::string method;
  std::string path;  // OpenAPI form: /v1/jobs/{id}
};
const std::vector<RouteInfo>& api_routes();

// Locates the soupuv CLI: the flag, then next to this executable, then the build tree.
std::string find_worker_binary(const std::string& configured);
std::string executable_dir();

}  // namespace soupuv::server
