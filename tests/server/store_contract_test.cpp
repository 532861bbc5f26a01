// The JobStore and BlobStore contracts, run against both implementations:
// the embedded SQLite store / data directory, and PostgreSQL (a real server
// started by pg_harness.h, one fresh database per test). Then the shared
// queue's own rules (job_queue.h), which only the PostgreSQL store has:
// SKIP LOCKED claims, leases, the reaper, owner-conditioned writes (the
// outcome naming the attempt whose result blobs count, so a late writer's
// are not the result), service-wide capacity and idempotency, TTL by the database clock, and
// migrations safe under concurrent starts.
#include <gtest/gtest.h>

#include <atomic>
#include <fstream>
#include <set>
#include <thread>

#include "harness.h"
#include "pg_harness.h"
#include "test_job.h"
#include "soupuv/server/blob_store.h"
#include "soupuv/server/files.h"
#include "soupuv/server/pg_job_store.h"
#include "soupuv/server/pg_schema.h"
#include "soupuv/server/result_blobs.h"
#include "soupuv/server/storage.h"

using namespace soupuv::server;
namespace fs = std::filesystem;

namespace {

soupuv::test::TempPostgres* shared_postgres() {
  static std::unique_ptr<soupuv::test::TempPostgres> pg = [] {
    if (soupuv::test::TempPostgres::bin_dir().empty()) return std::unique_ptr<soupuv::test::TempPostgres>();
    return std::make_unique<soupuv::test::TempPostgres>();
  }();
  return pg.get();
}

// A fresh migrated database (its URL), or "" with the test skipped (or failed in CI).
std::string fresh_pg_url() {
  auto* pg = shared_postgres();
  if (!pg || !pg->ok()) return "";
  std::string url = pg->fresh_database();
  if (url.empty()) return "";
  PgConnection c(url);
  migrate_pg_schema(c);
  return url;
}

#define REQUIRE_PG(url)                                                                         \
  do {                                                                                          \
    if ((url).empty()) {                                                                        \
      std::string why = shared_postgres() ? shared_postgres()->error() : "PostgreSQL not installed"; \
      if (soupuv::test::postgres_required()) FAIL() << "PostgreSQL needed in CI: " << why;      \
      GTEST_SKIP() << why;                                                                      \
    }                                                                                           \
  } while (0)

// One store under test with whatever keeps it alive.
struct Backend {
  std::unique_ptr<PgPool> pool;
  std::unique_ptr<DataDir> data;
  std::unique_ptr<JobStore> store;
  std::unique_ptr<BlobStore> blobs;
  std::string url;  // PostgreSQL only
  std::string db_path;  // SQLite only
};

Backend open_backend(const std::string& kind) {
  Backend b;
  b.data = std::make_unique<DataDir>(soupuv::test::fresh_dir("contract-" + kind));
  if (kind == "sqlite") {
    b.db_path = b.data->database().string();
    b.store = open_sqlite_job_store(b.db_path);
    b.blobs = open_file_blob_store(*b.data);
  } else {
    b.url = fresh_pg_url();
    if (b.url.empty()) return b;
    b.pool = std::make_unique<PgPool>(b.url, 4);
    b.store = std::make_unique<PgJobStore>(*b.pool);
    b.blobs = open_pg_blob_store(*b.pool);
  }
  return b;
}

Job new_job(const std::string& hash, const std::string& key = "", const std::string& tenant = "") {
  Job j = soupuv::test::upload_job(hash, 1234);
  j.idempotency_key = key;
  j.tenant = tenant;
  return j;
}

class StoreContract : public ::testing::TestWithParam<std::string> {};

TEST_P(StoreContract, LifecyclePagingIdempotencyAndPersistence) {
  Backend b = open_backend(GetParam());
  REQUIRE_PG(b.store ? std::string("ok") : std::string());
  std::vector<std::string> ids;
  for (int i = 0; i < 5; ++i) {
    Job j = new_job("h" + std::to_string(i), i == 0 ? "key-0" : "");
    auto stored = b.store->create_or_get_by_key(j);
    ASSERT_TRUE(stored);
    EXPECT_EQ(stored->id, j.id);
    EXPECT_EQ(stored->state, JobState::queued);
    EXPECT_NEAR(stored->created_at, now_seconds(), 60);
    ids.push_back(j.id);
  }
  Job dup = new_job("other", "key-0");
  auto existing = b.store->create_or_get_by_key(dup);
  ASSERT_TRUE(existing);
  EXPECT_EQ(existing->id, ids[0]);
  EXPECT_EQ(existing->request_hash, "h0");
  EXPECT_EQ(existing->idempotency_key, "key-0");
  // The same key of another tenant is another job.
  auto other = b.store->create_or_get_by_key(new_job("h9", "key-0", "alice"));
  ASSERT_TRUE(other);
  EXPECT_NE(other->id, ids[0]);
  EXPECT_EQ(other->tenant, "alice");
  b.store->remove(other->id);

  b.store->mark_running(ids[1], now_seconds());
  b.store->update_progress(ids[1], "load", 0.5, {{"parse", 0.1}});
  b.store->finish(ids[2], JobState::failed, JobError{"invalid_input", 400, "bad"}, {}, 0, now_seconds() - 100);
  b.store->finish(ids[3], JobState::succeeded, std::nullopt, {"result.glb"}, 1, now_seconds());
  b.store->request_cancel(ids[4]);

  auto p1 = b.store->list(std::nullopt, 2, "", std::nullopt);
  ASSERT_EQ(p1.jobs.size(), 2u);
  EXPECT_EQ(p1.jobs[0].id, ids[4]);  // newest first
  EXPECT_FALSE(p1.next_cursor.empty());
  auto p2 = b.store->list(std::nullopt, 2, p1.next_cursor, std::nullopt);
  ASSERT_EQ(p2.jobs.size(), 2u);
  EXPECT_EQ(p2.jobs[0].id, ids[2]);
  auto p3 = b.store->list(std::nullopt, 2, p2.next_cursor, std::nullopt);
  ASSERT_EQ(p3.jobs.size(), 1u);
  EXPECT_TRUE(p3.next_cursor.empty());
  auto failed = b.store->list(JobState::failed, 10, "", std::nullopt);
  ASSERT_EQ(failed.jobs.size(), 1u);
  EXPECT_EQ(failed.jobs[0].error->detail, "bad");
  EXPECT_EQ(failed.jobs[0].error->http_status, 400);
  EXPECT_EQ(b.store->list(std::nullopt, 10, "", std::string("alice")).jobs.size(), 0u);
  EXPECT_EQ(b.store->list(std::nullopt, 10, "", std::string("")).jobs.size(), 5u);
  auto counts = b.store->count_by_state();
  EXPECT_EQ(counts["queued"], 2);
  EXPECT_EQ(counts["running"], 1);
  EXPECT_EQ(counts["canceled"], 0);

  auto running = b.store->get(ids[1]);
  ASSERT_TRUE(running);
  EXPECT_EQ(running->state, JobState::running);
  EXPECT_EQ(running->stage, "load");
  EXPECT_DOUBLE_EQ(running->fraction, 0.5);
  EXPECT_EQ(running->stage_seconds["parse"], 0.1);
  EXPECT_EQ(running->attempts, 1);
  EXPECT_TRUE(b.store->get(ids[4])->cancel_requested);
  b.store->requeue(ids[1]);
  EXPECT_EQ(b.store->get(ids[1])->state, JobState::queued);
  EXPECT_EQ(b.store->get(ids[1])->attempts, 1);  // kept
  auto un = b.store->unfinished();
  ASSERT_EQ(un.size(), 3u);
  EXPECT_EQ(un[0].id, ids[0]);  // oldest first
  EXPECT_EQ(b.store->finished_before(now_seconds() - 50), std::vector<std::string>{ids[2]});
  b.store->remove(ids[2]);
  EXPECT_FALSE(b.store->get(ids[2]));
  EXPECT_EQ(b.store->get(ids[3])->outputs, std::vector<std::string>{"result.glb"});
  EXPECT_FALSE(b.store->get(new_job_id()));
}

// Whatever a client puts inside params (issue 22 adds metadata and
// callback_url there) round-trips whole, key order included.
TEST_P(StoreContract, ParamsJsonRoundTripsWhole) {
  Backend b = open_backend(GetParam());
  REQUIRE_PG(b.store ? std::string("ok") : std::string());
  Job j = new_job("h");
  j.params = nlohmann::json::parse(
      R"({"method":"box","texture_size":512,"metadata":{"asset":"chair-01","tags":["a","ü"]},)"
      R"("callback_url":"https://example.test/hook","seam_hints":[[[0,0,0],[1,1.5,2e-9]]]})");
  b.store->create_or_get_by_key(j);
  auto back = b.store->get(j.id);
  ASSERT_TRUE(back);
  EXPECT_EQ(back->params, j.params);
  EXPECT_EQ(back->params.dump(), j.params.dump());
}

// Reopening finds everything (what a restart relies on).
TEST_P(StoreContract, SurvivesReopen) {
  Backend b = open_backend(GetParam());
  REQUIRE_PG(b.store ? std::string("ok") : std::string());
  Job j = new_job("h", "k");
  b.store->create_or_get_by_key(j);
  b.store->finish(j.id, JobState::succeeded, std::nullopt, {"result.glb", "diagnostics.json"}, 1, now_seconds());
  b.store.reset();
  std::unique_ptr<JobStore> again;
  std::unique_ptr<PgPool> pool;
  if (GetParam() == "sqlite") {
    again = open_sqlite_job_store(b.db_path);
  } else {
    pool = std::make_unique<PgPool>(b.url, 1);
    again = std::make_unique<PgJobStore>(*pool);
  }
  auto back = again->get(j.id);
  ASSERT_TRUE(back);
  EXPECT_EQ(back->state, JobState::succeeded);
  EXPECT_EQ(back->outputs.size(), 2u);
  EXPECT_EQ(back->result_attempt, 1);
  EXPECT_EQ(back->idempotency_key, "k");
}

// Results are stored per attempt and the outcome names the attempt whose
// blobs are the job's result (result_blobs.h): what a reader resolves is that
// attempt's file whatever other attempts stored, and one attempt's blobs go
// without the others'.
TEST_P(StoreContract, OutcomeNamesTheAttemptWhoseBlobsAreTheResult) {
  Backend b = open_backend(GetParam());
  REQUIRE_PG(b.store ? std::string("ok") : std::string());
  Job j = new_job("h");
  b.store->create_or_get_by_key(j);
  const fs::path src = b.data->root() / "src.bin";
  auto put = [&](const std::string& name, const std::string& bytes) {
    std::ofstream(src, std::ios::binary) << bytes;
    b.blobs->put(j.id, name, src);
  };
  auto read = [&](const std::string& name) {
    std::string got;
    auto n = b.blobs->size(j.id, name);
    if (!n || !b.blobs->read(j.id, name, 0, *n, [&](const char* p, size_t len) { return got.append(p, len), true; }))
      return std::string("(missing)");
    return got;
  };
  put("input.glb", "input");
  put(attempt_blob(1, "result.glb"), "attempt one");
  put(attempt_blob(2, "result.glb"), "attempt two");
  put(attempt_blob(2, "diagnostics.json"), "{}");
  put(attempt_blob(10, "result.glb"), "attempt ten");  // attempt-1/ is not a prefix of attempt-10/
  b.store->mark_running(j.id, now_seconds());
  b.store->finish(j.id, JobState::succeeded, std::nullopt, {"result.glb", "diagnostics.json"}, 2, now_seconds());
  auto done = b.store->get(j.id);
  ASSERT_TRUE(done);
  EXPECT_EQ(done->result_attempt, 2);
  EXPECT_EQ(result_blob(*done, "result.glb"), "attempt-2/result.glb");
  EXPECT_EQ(read(result_blob(*done, "result.glb")), "attempt two");
  // A late write of attempt 1 changes nothing a reader of the job sees.
  put(attempt_blob(1, "result.glb"), "attempt one, late");
  EXPECT_EQ(read(result_blob(*b.store->get(j.id), "result.glb")), "attempt two");
  b.blobs->remove_attempt(j.id, 1);
  EXPECT_EQ(read(attempt_blob(1, "result.glb")), "(missing)");
  EXPECT_EQ(read(attempt_blob(2, "result.glb")), "attempt two");
  EXPECT_EQ(read(attempt_blob(2, "diagnostics.json")), "{}");
  EXPECT_EQ(read(attempt_blob(10, "result.glb")), "attempt ten");
  EXPECT_EQ(read("input.glb"), "input");
  // A job finished before results were per attempt reads the plain names.
  Job old = new_job("o");
  b.store->create_or_get_by_key(old);
  b.store->finish(old.id, JobState::succeeded, std::nullopt, {"result.glb"}, 0, now_seconds());
  EXPECT_EQ(result_blob(*b.store->get(old.id), "result.glb"), "result.glb");
  b.blobs->remove(j.id);
  EXPECT_EQ(read(attempt_blob(2, "result.glb")), "(missing)");
}

TEST_P(StoreContract, BlobsStreamInPiecesAndRanges) {
  Backend b = open_backend(GetParam());
  REQUIRE_PG(b.store ? std::string("ok") : std::string());
  const std::string id = new_job_id();
  // 2.5 chunks: reads cross row boundaries.
  std::string bytes(size_t(kBlobChunkBytes) * 5 / 2, '\0');
  for (size_t i = 0; i < bytes.size(); ++i) bytes[i] = char((i * 2654435761u) >> 13);
  const fs::path src = b.data->root() / "src.bin";
  auto write = [&](const fs::path& p, const std::string& s) {
    std::ofstream(p, std::ios::binary).write(s.data(), std::streamsize(s.size()));
  };
  write(src, bytes);
  b.blobs->put(id, "result.glb", src);
  write(src, "");
  b.blobs->put(id, "empty.json", src);
  EXPECT_EQ(b.blobs->size(id, "result.glb"), int64_t(bytes.size()));
  EXPECT_EQ(b.blobs->size(id, "empty.json"), 0);
  EXPECT_FALSE(b.blobs->size(id, "missing"));
  EXPECT_EQ(b.blobs->names(id), (std::vector<std::string>{"empty.json", "result.glb"}));
  // A range across the first chunk boundary, delivered in pieces no larger than a chunk.
  std::string got;
  size_t largest = 0;
  const int64_t off = kBlobChunkBytes - 1000, len = kBlobChunkBytes + 5000;
  ASSERT_TRUE(b.blobs->read(id, "result.glb", off, len, [&](const char* p, size_t n) {
    got.append(p, n);
    largest = std::max(largest, n);
    return true;
  }));
  EXPECT_EQ(got, bytes.substr(size_t(off), size_t(len)));
  EXPECT_LE(largest, size_t(kBlobChunkBytes));
  // A sink that stops stops the read.
  int calls = 0;
  EXPECT_FALSE(b.blobs->read(id, "result.glb", 0, int64_t(bytes.size()), [&](const char*, size_t) {
    ++calls;
    return false;
  }));
  EXPECT_EQ(calls, 1);
  const fs::path out = b.data->root() / "out.bin";
  ASSERT_TRUE(b.blobs->get(id, "result.glb", out));
  EXPECT_EQ(soupuv::test::read_bytes(out), bytes);
  EXPECT_FALSE(b.blobs->get(id, "missing", out));
  // put replaces.
  write(src, "second");
  b.blobs->put(id, "result.glb", src);
  EXPECT_EQ(b.blobs->size(id, "result.glb"), 6);
  b.blobs->remove(id);
  EXPECT_TRUE(b.blobs->names(id).empty());
  EXPECT_FALSE(b.blobs->size(id, "result.glb"));
}

INSTANTIATE_TEST_SUITE_P(Stores, StoreContract, ::testing::Values("sqlite", "postgres"),
                         [](const auto& info) { return info.param; });

// ---- the shared queue (PostgreSQL only) ----------------------------------------

struct Node {  // one server process's view: its own pool, the same database
  explicit Node(const std::string& url) : pool(url, 4), store(pool) {}
  PgPool pool;
  PgJobStore store;
};

TEST(SharedQueue, ConcurrentClaimersTakeEachJobOnce) {
  const std::string url = fresh_pg_url();
  REQUIRE_PG(url);
  Node setup(url);
  const int jobs = 120;
  for (int i = 0; i < jobs; ++i) ASSERT_EQ(setup.store.submit(new_job("h"), 1000).admission, Admission::accepted);
  std::mutex mu;
  std::multiset<std::string> claimed;
  std::vector<std::thread> threads;
  for (int t = 0; t < 8; ++t)
    threads.emplace_back([&, t] {
      Node node(url);
      while (auto c = node.store.claim("node" + std::to_string(t), 30)) {
        EXPECT_EQ(c->first.state, JobState::running);
        EXPECT_EQ(c->second.attempt, 1);
        EXPECT_TRUE(node.store.complete(c->second, JobState::succeeded, std::nullopt, {"result.glb"}));
        std::lock_guard lock(mu);
        claimed.insert(c->first.id);
      }
    });
  for (auto& t : threads) t.join();
  EXPECT_EQ(claimed.size(), size_t(jobs));
  EXPECT_EQ(std::set<std::string>(claimed.begin(), claimed.end()).size(), size_t(jobs));
  EXPECT_EQ(setup.store.count_by_state()["succeeded"], jobs);
}

TEST(SharedQueue, ClaimsInOrderAndOwnerConditionedWrites) {
  const std::string url = fresh_pg_url();
  REQUIRE_PG(url);
  Node a(url), b(url);
  Job j1 = new_job("1"), j2 = new_job("2");
  a.store.submit(j1, 10);
  b.store.submit(j2, 10);
  auto c1 = a.store.claim("a/0", 30);
  ASSERT_TRUE(c1);
  EXPECT_EQ(c1->first.id, j1.id);  // FIFO across nodes
  EXPECT_GT(c1->first.started_at, 0);
  EXPECT_TRUE(a.store.progress(c1->second, "proxy", 0.25, {{"load", 0.5}}));
  EXPECT_EQ(b.store.get(j1.id)->stage, "proxy");  // any node reads it
  // Another owner writes nothing.
  Lease forged = c1->second;
  forged.owner = "b/0";
  EXPECT_FALSE(b.store.progress(forged, "x", 1, {}));
  EXPECT_FALSE(b.store.complete(forged, JobState::succeeded, std::nullopt, {}));
  EXPECT_FALSE(b.store.release(forged));
  // The lease expires, the reaper gives the job to b: a's late writes miss.
  PgConnection(url).exec("UPDATE soupuv_jobs SET lease_until = now() - interval '1 second' WHERE id = $1", {j1.id});
  auto reaped = b.store.reap(3);
  EXPECT_EQ(reaped.requeued, std::vector<std::string>{j1.id});
  auto c2 = b.store.claim("b/0", 30);
  ASSERT_TRUE(c2);
  EXPECT_EQ(c2->first.id, j1.id);
  EXPECT_EQ(c2->second.attempt, 2);
  EXPECT_FALSE(a.store.complete(c1->second, JobState::succeeded, std::nullopt, {"result.glb"}));
  auto hb = a.store.heartbeat({c1->second}, 30);
  ASSERT_EQ(hb.size(), 1u);
  EXPECT_FALSE(hb[0].held);
  EXPECT_TRUE(b.store.complete(c2->second, JobState::succeeded, std::nullopt, {"result.glb"}));
  auto done = a.store.get(j1.id);
  EXPECT_EQ(done->state, JobState::succeeded);
  EXPECT_EQ(done->attempts, 2);
  EXPECT_EQ(done->result_attempt, 2);  // the lease's attempt, with the state
  EXPECT_GT(done->finished_at, 0);
}

// The window after a worker's last lease check: attempt 1 stores its result
// after attempt 2 took the job over and recorded its outcome. The job's
// result stays attempt 2's; attempt 1's refused complete() changes nothing.
TEST(SharedQueue, LateWriterOfALostLeaseIsNotTheResult) {
  const std::string url = fresh_pg_url();
  REQUIRE_PG(url);
  Node a(url), b(url);
  auto blobs = open_pg_blob_store(a.pool);
  const fs::path dir = soupuv::test::fresh_dir("late-writer-store");
  auto put = [&](const std::string& id, const std::string& name, const std::string& bytes) {
    std::ofstream(dir / "x", std::ios::binary) << bytes;
    blobs->put(id, name, dir / "x");
  };
  Job j = new_job("h");
  a.store.submit(j, 10);
  auto c1 = a.store.claim("a/0", 30);
  ASSERT_TRUE(c1);
  ASSERT_TRUE(a.store.heartbeat({c1->second}, 30)[0].held);  // a's last check: held
  PgConnection(url).exec("UPDATE soupuv_jobs SET lease_until = now() - interval '1 second' WHERE id = $1", {j.id});
  ASSERT_EQ(b.store.reap(3).requeued, std::vector<std::string>{j.id});
  auto c2 = b.store.claim("b/0", 30);
  ASSERT_TRUE(c2);
  put(j.id, attempt_blob(c2->second.attempt, "result.glb"), "attempt two");
  ASSERT_TRUE(b.store.complete(c2->second, JobState::succeeded, std::nullopt, {"result.glb"}));
  put(j.id, attempt_blob(c1->second.attempt, "result.glb"), "attempt one, late");
  EXPECT_FALSE(a.store.complete(c1->second, JobState::succeeded, std::nullopt, {"result.glb"}));
  auto done = b.store.get(j.id);
  ASSERT_TRUE(done);
  EXPECT_EQ(done->result_attempt, 2);
  std::string got;
  const std::string name = result_blob(*done, "result.glb");
  ASSERT_TRUE(blobs->read(j.id, name, 0, blobs->size(j.id, name).value_or(0), [&](const char* p, size_t n) {
    got.append(p, n);
    return true;
  }));
  EXPECT_EQ(got, "attempt two");
}

TEST(SharedQueue, HeartbeatKeepsLeaseAndCarriesCancel) {
  const std::string url = fresh_pg_url();
  REQUIRE_PG(url);
  Node a(url), b(url);
  Job j = new_job("h");
  a.store.submit(j, 10);
  // 4 s of heartbeats every 0.5 s on a 3 s lease: it outlives its first
  // term, with 2.5 s of slack per beat for a loaded machine.
  auto c = a.store.claim("a/0", 3);
  ASSERT_TRUE(c);
  for (int i = 0; i < 8; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    auto hb = a.store.heartbeat({c->second}, 3);
    ASSERT_TRUE(hb[0].held);
    EXPECT_FALSE(hb[0].cancel_requested);
    EXPECT_TRUE(b.store.reap(3).requeued.empty());
  }
  b.store.request_cancel(j.id);  // from another node
  EXPECT_FALSE(b.store.cancel_queued(j.id));  // it is running, not queued
  auto hb = a.store.heartbeat({c->second}, 3);
  EXPECT_TRUE(hb[0].held);
  EXPECT_TRUE(hb[0].cancel_requested);
  // A queued job is canceled at once.
  Job q = new_job("q");
  a.store.submit(q, 10);
  EXPECT_TRUE(b.store.cancel_queued(q.id));
  EXPECT_EQ(a.store.get(q.id)->state, JobState::canceled);
  EXPECT_FALSE(a.store.claim("a/1", 30));
}

TEST(SharedQueue, ReaperRequeuesThenFailsAtTheAttemptLimit) {
  const std::string url = fresh_pg_url();
  REQUIRE_PG(url);
  Node a(url);
  Job j = new_job("h");
  a.store.submit(j, 10);
  for (int attempt = 1; attempt <= 2; ++attempt) {
    auto c = a.store.claim("dead/0", 0.2);
    ASSERT_TRUE(c);
    EXPECT_EQ(c->second.attempt, attempt);
    std::this_thread::sleep_for(std::chrono::milliseconds(400));  // by the database's clock
    auto r = a.store.reap(2);
    if (attempt == 1) {
      EXPECT_EQ(r.requeued, std::vector<std::string>{j.id});
    } else {
      EXPECT_EQ(r.failed, std::vector<std::string>{j.id});
    }
  }
  auto failed = a.store.get(j.id);
  EXPECT_EQ(failed->state, JobState::failed);
  ASSERT_TRUE(failed->error);
  EXPECT_EQ(failed->error->code, "lost");
  EXPECT_NE(failed->error->detail.find("2 attempts"), std::string::npos) << failed->error->detail;
  EXPECT_GT(failed->finished_at, 0);
}

TEST(SharedQueue, CapacityAndIdempotencyAcrossNodes) {
  const std::string url = fresh_pg_url();
  REQUIRE_PG(url);
  // Four nodes submit 10 jobs each at once against a capacity of 25: exactly 25 in.
  std::atomic<int> accepted{0}, full{0};
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t)
    threads.emplace_back([&] {
      Node n(url);
      for (int i = 0; i < 10; ++i) {
        auto r = n.store.submit(new_job("h"), 25);
        (r.admission == Admission::accepted ? accepted : full)++;
      }
    });
  for (auto& t : threads) t.join();
  EXPECT_EQ(accepted.load(), 25);
  EXPECT_EQ(full.load(), 15);
  Node a(url), b(url);
  EXPECT_EQ(a.store.queued(), 25);
  // The same key on two nodes at once: one job.
  std::vector<SubmitAnswer> answers(2);
  std::thread t1([&] { answers[0] = a.store.submit(new_job("same", "idem-1", "alice"), 1000); });
  std::thread t2([&] { answers[1] = b.store.submit(new_job("same", "idem-1", "alice"), 1000); });
  t1.join();
  t2.join();
  ASSERT_TRUE(answers[0].job && answers[1].job);
  EXPECT_EQ(answers[0].job->id, answers[1].job->id);
  EXPECT_EQ(int(answers[0].admission == Admission::duplicate) + int(answers[1].admission == Admission::duplicate), 1);
  // A duplicate is answered even when the queue is full.
  EXPECT_EQ(a.store.submit(new_job("same", "idem-1", "alice"), 0).admission, Admission::duplicate);
}

TEST(SharedQueue, ExpireUsesTheDatabaseClockAndTakesBlobs) {
  const std::string url = fresh_pg_url();
  REQUIRE_PG(url);
  Node a(url);
  auto blobs = open_pg_blob_store(a.pool);
  fs::path dir = soupuv::test::fresh_dir("expire");
  Job old = new_job("o"), fresh = new_job("f");
  for (Job* j : {&old, &fresh}) {
    a.store.submit(*j, 10);
    std::ofstream(dir / "x") << "bytes";
    blobs->put(j->id, "result.glb", dir / "x");
    auto c = a.store.claim("n/0", 30);
    ASSERT_TRUE(a.store.complete(c->second, JobState::succeeded, std::nullopt, {"result.glb"}));
  }
  // finished_at is the database's now(); age one by an hour.
  PgConnection(url).exec("UPDATE soupuv_jobs SET finished_at = finished_at - 3600 WHERE id = $1", {old.id});
  EXPECT_EQ(a.store.expire(1800), std::vector<std::string>{old.id});
  EXPECT_FALSE(a.store.get(old.id));
  EXPECT_FALSE(blobs->size(old.id, "result.glb"));
  EXPECT_TRUE(a.store.get(fresh.id));
  EXPECT_TRUE(blobs->size(fresh.id, "result.glb"));
  EXPECT_TRUE(a.store.expire(1800).empty());
}

TEST(SharedQueue, MigrationsAreSafeWhenNodesStartTogether) {
  auto* pg = shared_postgres();
  const std::string url = pg && pg->ok() ? pg->fresh_database() : "";
  REQUIRE_PG(url);
  std::atomic<int> applied{0}, errors{0};
  std::vector<std::thread> threads;
  for (int t = 0; t < 6; ++t)
    threads.emplace_back([&] {
      try {
        PgConnection c(url);
        applied += migrate_pg_schema(c);
      } catch (const std::exception& e) {
        ++errors;
        ADD_FAILURE() << e.what();
      }
    });
  for (auto& t : threads) t.join();
  EXPECT_EQ(errors.load(), 0);
  EXPECT_EQ(applied.load(), pg_schema_version());  // each migration once, by whichever node came first
  PgConnection c(url);
  EXPECT_EQ(c.exec("SELECT COUNT(*) FROM soupuv_schema_migrations").integer(0, 0), pg_schema_version());
  EXPECT_EQ(migrate_pg_schema(c), 0);
  // A newer schema than this build knows: refused, never downgraded.
  c.exec("INSERT INTO soupuv_schema_migrations (version, name) VALUES (999, 'future')");
  EXPECT_THROW(migrate_pg_schema(c), std::runtime_error);
}

TEST(SharedQueue, ReconnectsAfterPostgresRestart) {
  // Its own server: restarting the shared one would disturb other tests.
  soupuv::test::TempPostgres pg;
  if (!pg.ok()) {
    if (soupuv::test::postgres_required()) FAIL() << pg.error();
    GTEST_SKIP() << pg.error();
  }
  PgPool pool(pg.url(), 2);
  {
    auto c = pool.take();
    migrate_pg_schema(*c);
  }
  PgJobStore store(pool);
  Job j = new_job("h");
  store.submit(j, 10);
  pg.stop();
  EXPECT_THROW(store.get(j.id), StorageUnavailable);  // 503 at the API, a retry in the supervisor
  pg.start();
  ASSERT_TRUE(pg.ok()) << pg.error();
  auto back = store.get(j.id);  // the pooled connections were dead: renewed transparently
  ASSERT_TRUE(back);
  EXPECT_EQ(back->state, JobState::queued);
}

}  // namespace
