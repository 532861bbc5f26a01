// Scale-out on loopback, end to end with real components: a PostgreSQL
// server in a temporary directory (pg_harness.h), three soupuv-server
// processes sharing it (--database-url), the real soupuv CLI as their worker.
//
//   30 jobs (the bunny soup, box method: about a second each) submitted
//   round-robin over the nodes; one node SIGKILLed while it runs a job; its
//   jobs must be re-run by the others within lease + 10 s. PostgreSQL is then
//   restarted while jobs run and more are submitted: nodes reconnect and
//   carry on. Every job succeeds, every result downloads from every
//   surviving node, byte-identical and valid; no job's completion is
//   recorded twice (lease-conditioned writes); after the TTL, nothing is
//   left: no row, no blob, no scratch file.
#include <gtest/gtest.h>

#include <chrono>
#include <map>
#include <mutex>
#include <regex>
#include <set>
#include <sstream>
#include <thread>

#include "harness.h"
#include "pg_harness.h"
#include "soupuv/server/pg_connection.h"

namespace fs = std::filesystem;
using soupuv::server::PgConnection;
using soupuv::server::PgParam;
using namespace soupuv::test;

namespace {

double wall() { return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count(); }

std::string node_id_of(const ServerProcess& s) {
  static const std::regex re("\"msg\":\"database\".*\"node\":\"([^\"]+)\"");
  std::smatch m;
  const std::string log = s.log();
  return std::regex_search(log, m, re) ? std::string(m[1]) : "";
}

// A GLB whose header, length and JSON chunk are sound, with UVs.
::testing::AssertionResult valid_glb(const std::string& b) {
  auto u32 = [&](size_t at) {
    return uint32_t(uint8_t(b[at])) | uint32_t(uint8_t(b[at + 1])) << 8 | uint32_t(uint8_t(b[at + 2])) << 16 |
           uint32_t(uint8_t(b[at + 3])) << 24;
  };
  if (b.size() < 20 || b.compare(0, 4, "glTF") != 0) return ::testing::AssertionFailure() << "no glTF magic";
  if (u32(8) != b.size()) return ::testing::AssertionFailure() << "header length " << u32(8) << " != " << b.size();
  const uint32_t json_len = u32(12);
  if (u32(16) != 0x4E4F534A || 20 + json_len > b.size()) return ::testing::AssertionFailure() << "no JSON chunk";
  auto j = nlohmann::json::parse(b.substr(20, json_len), nullptr, false);
  if (!j.is_object() || !j.contains("meshes")) return ::testing::AssertionFailure() << "JSON chunk without meshes";
  if (b.substr(20, json_len).find("TEXCOORD_0") == std::string::npos)
    return ::testing::AssertionFailure() << "no TEXCOORD_0";
  return ::testing::AssertionSuccess();
}

// "job finished" log lines with state succeeded, by job id.
std::map<std::string, int> completions(const std::string& log) {
  std::map<std::string, int> out;
  std::istringstream in(log);
  std::string line;
  while (std::getline(in, line)) {
    auto j = nlohmann::json::parse(line, nullptr, false);
    if (j.is_object() && j.value("msg", "") == "job finished" && j.value("state", "") == "succeeded")
      ++out[j.value("job", "")];
  }
  return out;
}

}  // namespace

TEST(Cluster, ThreeNodesSurviveANodeKillAndAPostgresRestart) {
  if (!cli_available()) GTEST_SKIP() << "the soupuv CLI was not built";
  TempPostgres pg;
  if (!pg.ok()) {
    if (postgres_required()) FAIL() << pg.error();
    GTEST_SKIP() << pg.error();
  }
  const double t0 = wall();
  const int lease = 5;
  const std::vector<std::string> args = {"--database-url", pg.url(), "--workers", "1", "--threads", "1",
                                         "--lease-seconds", std::to_string(lease), "--max-attempts", "4",
                                         "--queue-capacity", "100", "--result-ttl", "3600",
                                         "--poll-interval-ms", "500"};
  std::vector<fs::path> dirs;
  std::vector<std::unique_ptr<ServerProcess>> nodes;
  for (int i = 0; i < 3; ++i) {
    dirs.push_back(fresh_dir("cluster-node" + std::to_string(i)));
    nodes.push_back(std::make_unique<ServerProcess>(dirs.back(), args));
  }
  const std::string victim_node = node_id_of(*nodes[1]);
  ASSERT_FALSE(victim_node.empty()) << nodes[1]->log();
  const std::string soup = read_bytes(shared_data("soups/stanford-bunny-soup.glb"));

  std::mutex ids_mu;
  std::vector<std::string> ids;
  auto submit_to = [&](int node) {
    auto c = nodes[size_t(node)]->client();
    c.set_read_timeout(60, 0);
    for (int tries = 0; tries < 100; ++tries) {
      auto r = submit(c, soup, "model/gltf-binary", "?method=box");
      if (r && r->status == 202) {
        std::lock_guard lock(ids_mu);
        ids.push_back(nlohmann::json::parse(r->body)["id"]);
        return;
      }
      // 503 while PostgreSQL restarts: the client comes back, as Retry-After says.
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
    }
    ADD_FAILURE() << "node " << node << " never accepted a job";
  };
  // `n` jobs over `which` nodes, one client thread per node (uploads are
  // checked by `soupuv inspect` on the receiving node: in parallel, as clients would).
  auto submit_many = [&](int n, std::vector<int> which) {
    std::vector<std::thread> clients;
    for (size_t k = 0; k < which.size(); ++k)
      clients.emplace_back([&, k] {
        for (int i = int(k); i < n; i += int(which.size())) submit_to(which[k]);
      });
    for (auto& t : clients) t.join();
  };
  submit_many(18, {0, 1, 2});
  ASSERT_EQ(ids.size(), 18u);

  // SIGKILL node 1 while it holds a lease (asked of the database, not guessed).
  PgConnection db(pg.url());
  std::vector<std::string> victim_jobs;
  for (int i = 0; i < 600 && victim_jobs.empty(); ++i) {
    auto r = db.exec("SELECT id FROM soupuv_jobs WHERE state = 'running' AND lease_owner LIKE $1",
                     {PgParam(victim_node + "/%")});
    for (int k = 0; k < r.rows(); ++k) victim_jobs.push_back(r.text(k, 0));
    if (victim_jobs.empty()) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  ASSERT_FALSE(victim_jobs.empty()) << "node 1 never ran a job";
  nodes[1]->kill_hard();
  const double killed_at = wall();

  // Its jobs come back through the reaper and finish on the other nodes.
  auto c0 = nodes[0]->client();
  double recovered_at = 0;
  for (const auto& id : victim_jobs) {
    auto j = wait_finished(c0, id, lease + 60);
    EXPECT_EQ(j["state"], "succeeded") << j.dump();
    EXPECT_GE(j["attempts"].get<int>(), 2) << j.dump();
    recovered_at = std::max(recovered_at, wall());
  }
  const double recovery = recovered_at - killed_at;
  EXPECT_LE(recovery, lease + 10.0) << "the killed node's jobs took " << recovery << " s to finish elsewhere";

  // PostgreSQL restarted under queued and running jobs; more submitted after.
  submit_many(6, {0, 2});
  const int64_t in_flight =
      db.exec("SELECT COUNT(*) FROM soupuv_jobs WHERE state IN ('queued', 'running')").integer(0, 0);
  const double stop_at = wall();
  pg.stop();
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  pg.start();
  ASSERT_TRUE(pg.ok()) << pg.error();
  const double restarted_at = wall();
  EXPECT_GE(in_flight, 1) << "nothing was in flight when PostgreSQL restarted";
  submit_many(6, {0, 2});
  ASSERT_EQ(ids.size(), 30u);

  // Everything succeeds; results download from both survivors, identical and valid.
  auto c2 = nodes[2]->client();
  int after_restart = 0;
  for (const auto& id : ids) {
    auto j = wait_finished(c0, id, 180);
    ASSERT_EQ(j["state"], "succeeded") << j.dump();
    auto r0 = c0.Get(("/v1/jobs/" + id + "/result").c_str());
    auto r2 = c2.Get(("/v1/jobs/" + id + "/result").c_str());
    ASSERT_TRUE(r0 && r2);
    ASSERT_EQ(r0->status, 200) << r0->body;
    ASSERT_EQ(r2->status, 200) << r2->body;
    EXPECT_EQ(r0->body, r2->body);
    EXPECT_TRUE(valid_glb(r0->body)) << id;
    auto d2 = c2.Get(("/v1/jobs/" + id + "/diagnostics").c_str());
    ASSERT_TRUE(d2);
    EXPECT_EQ(d2->status, 200);
    EXPECT_TRUE(nlohmann::json::parse(d2->body, nullptr, false).is_object());
    auto f = db.exec("SELECT finished_at FROM soupuv_jobs WHERE id = $1", {PgParam(id)});
    if (f.rows() && f.real(0, 0) > restarted_at) ++after_restart;
  }
  EXPECT_GE(after_restart, 6 + int(in_flight > 0)) << "jobs finished after the PostgreSQL restart";

  // No completion recorded twice: each job's "job finished" success line
  // appears once over all three logs (the killed node's up to its death).
  std::map<std::string, int> done;
  for (const auto& n : nodes)
    for (const auto& [id, k] : completions(n->log())) done[id] += k;
  for (const auto& id : ids) EXPECT_EQ(done[id], 1) << id;
  EXPECT_EQ(done.size(), ids.size());
  // Every node took part (the queue is shared, not partitioned).
  for (int i : {0, 2}) EXPECT_FALSE(completions(nodes[size_t(i)]->log()).empty()) << "node " << i << " ran nothing";
  const std::string survivors = nodes[0]->log() + nodes[2]->log();
  EXPECT_NE(survivors.find("lease expired; job queued again"), std::string::npos);

  // The TTL: the survivors stop, one node with a 1 s TTL starts; its sweeper
  // (the database's clock) removes every job with its blobs.
  nodes[0]->terminate();
  nodes[2]->terminate();
  std::vector<std::string> ttl_args = args;
  ttl_args[std::find(ttl_args.begin(), ttl_args.end(), "--result-ttl") - ttl_args.begin() + 1] = "1";
  auto sweeper = std::make_unique<ServerProcess>(fresh_dir("cluster-node3"), ttl_args);
  int64_t rows = -1, blobs = -1, chunks = -1;
  for (int i = 0; i < 100; ++i) {
    rows = db.exec("SELECT COUNT(*) FROM soupuv_jobs").integer(0, 0);
    blobs = db.exec("SELECT COUNT(*) FROM soupuv_blobs").integer(0, 0);
    chunks = db.exec("SELECT COUNT(*) FROM soupuv_blob_chunks").integer(0, 0);
    if (rows + blobs + chunks == 0) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }
  EXPECT_EQ(rows, 0);
  EXPECT_EQ(blobs, 0);
  EXPECT_EQ(chunks, 0);
  // No scratch left on the survivors: inputs and work dirs go after each attempt.
  for (int i : {0, 2}) {
    int left = 0;
    for (const char* sub : {"jobs", "tmp"})
      for ([[maybe_unused]] const auto& e : fs::directory_iterator(dirs[size_t(i)] / sub)) ++left;
    EXPECT_EQ(left, 0) << "node " << i;
  }
  std::printf("cluster: %zu jobs, killed node's %zu job(s) finished elsewhere %.1f s after the kill (lease %d s); "
              "PostgreSQL down %.1f s with %lld jobs in flight, %d finished after it; whole test %.1f s\n",
              ids.size(), victim_jobs.size(), recovery, lease, restarted_at - stop_at, (long long)in_flight,
              after_restart, wall() - t0);
}
