// soupuv-bench store: the shared queue's throughput (job_queue.h) against a
// real PostgreSQL. 16 claimers (each its own connection, like 16 worker slots
// over several nodes) loop claim -> heartbeat -> complete on empty jobs
// until the queue is drained; jobs/s is completed jobs over wall time. The
// target (issue 20): >= 1,000 jobs/s, so that the queue is never what limits
// a fleet whose jobs take seconds.
//
//   soupuv-bench store [--quick] [--database-url URL] [--jobs N] [--claimers K] [--fsync on|off]
//
// Without --database-url a PostgreSQL server is started in a temporary
// directory (initdb + pg_ctl, fsync on: commits are durable, as in
// production). With one, a fresh database soupuv_bench_<pid> is created on
// that server and dropped afterwards: the bench never touches a live queue.
#include <atomic>
#include <chrono>
#include <iostream>
#include <thread>

#include "bench_registry.h"
#include "pg_harness.h"
#include "soupuv/server/files.h"
#include "soupuv/server/pg_job_store.h"
#include "soupuv/server/pg_schema.h"

namespace soupuv::bench {
namespace {

using namespace soupuv::server;

std::string with_database(const std::string& url, const std::string& db) {
  // postgresql://user@host:port/olddb?x -> .../db?x
  const size_t scheme = url.find("://");
  const size_t slash = url.find('/', scheme == std::string::npos ? 0 : scheme + 3);
  const size_t query = url.find('?', slash == std::string::npos ? 0 : slash);
  std::string base = slash == std::string::npos ? url : url.substr(0, slash);
  return base + "/" + db + (query == std::string::npos ? "" : url.substr(query));
}

int run_store(const Args& args) {
  std::string url, commit_delay;
  int jobs = args.quick ? 2000 : 20000, claimers = 16;
  bool fsync = true;
  for (size_t i = 0; i + 1 < args.rest.size(); ++i) {
    if (args.rest[i] == "--database-url") url = args.rest[++i];
    else if (args.rest[i] == "--jobs") jobs = std::stoi(args.rest[++i]);
    else if (args.rest[i] == "--claimers") claimers = std::stoi(args.rest[++i]);
    else if (args.rest[i] == "--fsync") fsync = args.rest[++i] != "off";
    else if (args.rest[i] == "--commit-delay") commit_delay = args.rest[++i];
  }
  std::unique_ptr<soupuv::test::TempPostgres> temp;
  if (url.empty()) {
    std::cerr << "store: starting a temporary PostgreSQL (fsync " << (fsync ? "on" : "off") << ")\n";
    temp = std::make_unique<soupuv::test::TempPostgres>(fsync);
    if (!temp->ok()) throw std::runtime_error(temp->error());
    url = temp->url();
  }
  const std::string db = "soupuv_bench_" + std::to_string(getpid());
  PgConnection admin(url);
  if (temp && !commit_delay.empty()) {
    // Group commit (a server setting, docs: "WAL Configuration"): committers
    // arriving within the delay share one WAL flush.
    admin.exec("ALTER SYSTEM SET commit_delay = " + std::to_string(std::stoi(commit_delay)));
    admin.exec("SELECT pg_reload_conf()");
  }
  admin.exec("CREATE DATABASE " + db);
  const std::string bench_url = with_database(url, db);
  struct Drop {
    PgConnection& admin;
    std::string db;
    ~Drop() {
      try {
        admin.exec("DROP DATABASE IF EXISTS " + db + " WITH (FORCE)");
      } catch (...) {
      }
    }
  } drop{admin, db};
  {
    PgConnection c(bench_url);
    migrate_pg_schema(c);
  }

  // Fill the queue in one statement: the bench measures the claim path.
  // (Submissions go through JobQueue::submit's capacity lock and COUNT, sized
  // for a queue bounded by --queue-capacity, not for 20,000 waiting jobs.)
  {
    PgConnection c(bench_url);
    c.exec("INSERT INTO soupuv_jobs (id, state, created_at, params, input_file, content_type, input_bytes,"
           " request_hash) SELECT 'bench' || g, 'queued', EXTRACT(EPOCH FROM now()), '{\"method\":\"box\"}',"
           " 'input.glb', 'model/gltf-binary', 0, 'bench' FROM generate_series(1, $1) AS g",
           {pg_int(jobs)});
    c.exec("ANALYZE soupuv_jobs");
  }
  std::atomic<int> done{0}, lost{0};
  auto t0 = std::chrono::steady_clock::now();
  std::vector<std::thread> threads;
  for (int t = 0; t < claimers; ++t)
    threads.emplace_back([&, t] {
      PgPool pool(bench_url, 1), advisory(bench_url, 1, kAdvisoryWrites);  // as a node has them
      PgJobStore store(pool, &advisory);
      const std::string owner = "bench/" + std::to_string(t);
      while (auto c = store.claim(owner, 30)) {
        auto hb = store.heartbeat({c->second}, 30);
        if (hb.empty() || !hb[0].held) ++lost;
        if (store.complete(c->second, JobState::succeeded, std::nullopt, {"result.glb"})) ++done;
        else ++lost;
      }
    });
  for (auto& t : threads) t.join();
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double rate = done / secs;
  emit({{"kind", "claim_heartbeat_complete"}, {"claimers", claimers}, {"jobs", done.load()}, {"lost", lost.load()},
        {"seconds", secs}, {"jobs_per_s", rate}, {"statements_per_job", 3}});
  const bool pass = done == jobs && lost == 0 && rate >= 1000;
  emit({{"kind", "summary"}, {"jobs_per_s", rate}, {"target_jobs_per_s", 1000}, {"pass", pass},
        {"fsync", temp ? (fsync ? "on (temporary server)" : "off (temporary server)") : "as configured"},
        {"commit_delay_us", commit_delay.empty() ? "server default" : commit_delay}});
  return pass ? 0 : 1;
}

Suite reg("store", "shared job queue on PostgreSQL: claim -> heartbeat -> complete, 16 claimers (jobs/s)", run_store);

}  // namespace
}  // namespace soupuv::bench
