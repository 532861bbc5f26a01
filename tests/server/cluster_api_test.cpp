// The API's service-wide promises with --database-url, over HTTP, on two
// nodes sharing a real PostgreSQL (pg_harness.h). The worker is the protocol
// double (worker_double.sh, "slow": a job lasts as long as the test wants;
// "stamp": each run's result differs), so these test the server, never a
// mapping.
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <thread>

#include "frozen_node.h"
#include "harness.h"
#include "pg_harness.h"
#include "test_job.h"
#include "soupuv/server/blob_store.h"
#include "soupuv/server/files.h"
#include "soupuv/server/metrics.h"
#include "soupuv/server/pg_job_store.h"
#include "soupuv/server/pg_schema.h"
#include "soupuv/server/scheduler.h"

namespace fs = std::filesystem;
using namespace soupuv::test;

namespace {

#define START_POSTGRES(pg)                                        \
  TempPostgres pg;                                                \
  if (!pg.ok()) {                                                 \
    if (postgres_required()) FAIL() << pg.error();                \
    GTEST_SKIP() << pg.error();                                   \
  }

}  // namespace

// A cancel sent to one node stops the worker running the job on the other,
// at once (NOTIFY), and capacity is the service's: one node refuses what the
// other filled.
TEST(ClusterApi, CancelReachesTheOtherNodeAndCapacityIsShared) {
  START_POSTGRES(pg);
  const std::vector<std::string> args = {"--database-url", pg.url(), "--workers", "1", "--queue-capacity", "1",
                                         "--lease-seconds", "10"};
  std::unique_ptr<ServerProcess> nodes[2] = {with_double("capi-a", "slow", args, "60"),
                                             with_double("capi-b", "slow", args, "60")};
  httplib::Client clients[2] = {nodes[0]->client(), nodes[1]->client()};
  // Two jobs: one runs on each node's only worker.
  const std::string first = submit_box(clients[0]), second = submit_box(clients[1]);
  ASSERT_FALSE(first.empty());
  ASSERT_FALSE(second.empty());
  wait_state(clients[0], first, "running", 20);
  wait_state(clients[1], second, "running", 20);
  // The third waits: the service's one queued place.
  const std::string queued = submit_box(clients[0]);
  ASSERT_FALSE(queued.empty());
  for (auto& c : clients) {
    auto full = submit(c, read_bytes(shared_data("gltf/Box.glb")), "model/gltf-binary");
    ASSERT_TRUE(full);
    EXPECT_EQ(full->status, 429) << full->body;
    EXPECT_TRUE(full->has_header("Retry-After"));
    EXPECT_NE(full->body.find("/problems/queue-full"), std::string::npos);
  }
  // Cancel of the queued job on the other node: done at once, 200.
  auto cq = clients[1].Post(("/v1/jobs/" + queued + ":cancel").c_str());
  ASSERT_TRUE(cq);
  EXPECT_EQ(cq->status, 200) << cq->body;
  // Which node runs `first`? Its log says so; cancel it through the other.
  int runner = -1;
  for (int i = 0; i < 2; ++i) {
    std::istringstream log(nodes[i]->log());
    for (std::string line; std::getline(log, line);) {
      auto l = nlohmann::json::parse(line, nullptr, false);
      if (l.is_object() && l.value("msg", "") == "job started" && l.value("job", "") == first) runner = i;
    }
  }
  ASSERT_GE(runner, 0);
  const int other = 1 - runner;
  const auto t0 = std::chrono::steady_clock::now();
  auto cr = clients[other].Post(("/v1/jobs/" + first + ":cancel").c_str());
  ASSERT_TRUE(cr);
  // 202 (the cancel is on its way), or 200 when the other node was quicker
  // than this answer's read of the row.
  EXPECT_TRUE(cr->status == 202 || cr->status == 200) << cr->status << " " << cr->body;
  auto j = wait_finished(clients[other], first, 20);
  EXPECT_EQ(j["state"], "canceled") << j.dump();
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 10.0);
  // Room again (a worker is free and the queue is empty): accepted anywhere.
  EXPECT_FALSE(submit_box(clients[other]).empty());
  for (auto& c : clients) c.Post(("/v1/jobs/" + second + ":cancel").c_str());
}

// The same Idempotency-Key sent to both nodes is one job; results and
// deletes work from either node; the upload's bytes come back whole.
TEST(ClusterApi, IdempotencyDownloadsAndDeleteAcrossNodes) {
  START_POSTGRES(pg);
  const std::vector<std::string> args = {"--database-url", pg.url(), "--workers", "1"};
  auto a = with_double("capi-c", "slow", args, "0");
  auto b = with_double("capi-d", "slow", args, "0");
  auto c_a = a->client(), c_b = b->client();
  const std::string box = read_bytes(shared_data("gltf/Box.glb"));
  auto r1 = submit(c_a, box, "model/gltf-binary", "", {{"Idempotency-Key", "same-key"}});
  auto r2 = submit(c_b, box, "model/gltf-binary", "", {{"Idempotency-Key", "same-key"}});
  ASSERT_TRUE(r1 && r2);
  ASSERT_EQ(r1->status, 202) << r1->body;
  ASSERT_EQ(r2->status, 202) << r2->body;
  const std::string id = nlohmann::json::parse(r1->body)["id"];
  EXPECT_EQ(nlohmann::json::parse(r2->body)["id"], id);
  EXPECT_EQ(r2->get_header_value("Idempotent-Replayed"), "true");
  // A different request under the same key: 422 on the other node too.
  auto r3 = submit(c_b, box, "model/gltf-binary", "?texture_size=128", {{"Idempotency-Key", "same-key"}});
  ASSERT_TRUE(r3);
  EXPECT_EQ(r3->status, 422);
  auto j = wait_finished(c_b, id, 30);
  ASSERT_EQ(j["state"], "succeeded") << j.dump();
  // The double copies its input to the result: the bytes went through the
  // blob store twice (upload, result) and come back from both nodes.
  for (auto* c : {&c_a, &c_b}) {
    auto res = c->Get(("/v1/jobs/" + id + "/result").c_str());
    ASSERT_TRUE(res);
    EXPECT_EQ(res->status, 200);
    EXPECT_EQ(res->body, box);
  }
  EXPECT_EQ(c_b.Get(("/v1/jobs/" + id + "/nothing").c_str())->status, 404);
  auto del = c_b.Delete(("/v1/jobs/" + id).c_str());
  ASSERT_TRUE(del);
  EXPECT_EQ(del->status, 204);
  EXPECT_EQ(c_a.Get(("/v1/jobs/" + id).c_str())->status, 404);
  EXPECT_EQ(c_a.Get(("/v1/jobs/" + id + "/result").c_str())->status, 404);
  // /readyz reports the database, /metrics the service-wide counts.
  auto ready = c_a.Get("/readyz");
  EXPECT_EQ(ready->status, 200) << ready->body;
  EXPECT_NE(ready->body.find("\"database\":true"), std::string::npos);
  auto m = c_a.Get("/metrics");
  EXPECT_NE(m->body.find("soupuv_leases_reaped_total"), std::string::npos);
  EXPECT_NE(m->body.find("soupuv_queue_depth 0"), std::string::npos);
}

// A folder upload (a .gltf with its buffer and image as parts) on a node of
// the shared store: every file of the folder goes through the blob store, so
// the node that runs the job (the real CLI) finds the .bin and the image.
TEST(ClusterApi, FolderUploadRunsFromTheSharedStore) {
  if (!cli_available()) GTEST_SKIP() << "the soupuv CLI was not built; end-to-end tests need it";
  START_POSTGRES(pg);
  ServerProcess node(fresh_dir("capi-folder"), {"--database-url", pg.url(), "--worker-bin", SOUPUV_CLI_BIN,
                                                "--workers", "1", "--threads", "2"});
  auto c = node.client();
  httplib::MultipartFormDataItems items = two_sided_plane_parts(R"({"method":"box","texture_size":128})");
  auto r = c.Post("/v1/jobs", items);
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 202) << r->body;
  const auto done = wait_finished(c, nlohmann::json::parse(r->body)["id"], 120);
  EXPECT_EQ(done["state"], "succeeded") << done.dump();
}

// The window a lease check cannot close. Node A's worker finished; A asked
// the database whether its lease still held (yes) and then froze before
// storing its result. While it was frozen its lease lapsed and node B ran
// the job again and recorded its outcome. A then thawed and stored its
// result after all (its complete() is refused, but the blobs were written).
// What downloads must stay B's result, byte for byte.
//
// Node A is an in-process Scheduler behind FrozenNodeQueue (frozen_node.h);
// node B a real server. The worker double in `stamp` mode makes each run's
// result and diagnostics different, so an overwrite shows.
TEST(ClusterApi, LateWriterAfterALostLeaseDoesNotChangeTheDownload) {
  using namespace soupuv::server;
  START_POSTGRES(pg);
  {
    PgConnection c(pg.url());
    migrate_pg_schema(c);
  }
  // The job, with its input in the blob store, as a node's upload leaves it.
  PgPool pool(pg.url(), 4);
  PgJobStore store(pool);
  auto blobs = open_pg_blob_store(pool);
  const fs::path dir = fresh_dir("late-writer-a");
  std::ofstream(dir / "upload.glb") << "the input bytes\n";
  Job job = upload_job("late-writer", 16);
  blobs->put(job.id, "input.glb", dir / "upload.glb");
  ASSERT_EQ(store.submit(job, 10).admission, Admission::accepted);

  // Node A: runs attempt 1 and freezes after its last lease check.
  Config config;
  config.workers = 1;
  config.threads = 1;
  config.lease_seconds = 2;
  config.poll_interval_ms = 200;
  config.worker_env = {"SOUPUV_TEST_WORKER_MODE", "SOUPUV_TEST_WORKER_SECONDS"};
  setenv("SOUPUV_TEST_WORKER_MODE", "stamp", 1);
  setenv("SOUPUV_TEST_WORKER_SECONDS", "0", 1);
  DataDir data(dir / "data");
  Metrics metrics;
  FrozenNodeQueue frozen(store);
  Scheduler a(config, SOUPUV_WORKER_DOUBLE, probe_worker(SOUPUV_WORKER_DOUBLE), store, data, metrics, *blobs, &frozen,
              "frozen-a");
  a.start();
  ASSERT_TRUE(frozen.wait_frozen(30)) << "node A never reached its last lease check";

  // Node B: its reaper takes the lapsed lease, its worker runs attempt 2.
  auto b = with_double("late-writer-b", "stamp",
                       {"--database-url", pg.url(), "--workers", "1", "--lease-seconds", "5", "--poll-interval-ms",
                        "200"},
                       "0");
  auto c = b->client();
  auto done = wait_finished(c, job.id, 30);
  ASSERT_EQ(done["state"], "succeeded") << done.dump();
  EXPECT_EQ(done["attempts"], 2);
  auto download = [&](const std::string& what) {
    auto r = c.Get(("/v1/jobs/" + job.id + "/" + what).c_str());
    return r && r->status == 200 ? r->body : std::string("(no ") + what + ")";
  };
  const std::string result = download("result"), diagnostics = download("diagnostics");
  ASSERT_NE(result.find("the input bytes"), std::string::npos) << result;

  // A thaws and goes on with its stale "held": it stores attempt 1's files.
  frozen.thaw();
  for (int i = 0; i < 200 && a.busy_workers() > 0; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(100));
  EXPECT_EQ(a.busy_workers(), 0);
  a.stop();
  unsetenv("SOUPUV_TEST_WORKER_MODE");
  unsetenv("SOUPUV_TEST_WORKER_SECONDS");

  EXPECT_EQ(download("result"), result) << "the late writer of attempt 1 replaced attempt 2's result";
  EXPECT_EQ(download("diagnostics"), diagnostics);
  auto after = wait_finished(c, job.id, 5);
  EXPECT_EQ(after["state"], "succeeded");
  EXPECT_EQ(after["attempts"], 2);
  // The loser's files are gone at once, not left for the TTL sweep.
  for (const auto& name : blobs->names(job.id))
    EXPECT_EQ(name.rfind("attempt-1/", 0), std::string::npos) << name;
}
