// A full disk is a refusal, not a crash loop (issue 21, item 4): uploads that
// would leave less than --min-free-mb get 503 + Retry-After and /readyz fails;
// ENOSPC is StorageUnavailable; a job store that fails its writes never
// terminates the server (writes are retried, the worker threads live on);
// temp files of killed workers are swept.
#include <gtest/gtest.h>

#include <stdlib.h>

#include <atomic>
#include <chrono>
#include <fstream>

#include "harness.h"
#include "soupuv/server/files.h"
#include "soupuv/server/job_store.h"
#include "soupuv/server/metrics.h"
#include "soupuv/server/scheduler.h"
#include "soupuv/server/storage.h"

using namespace soupuv::test;
using nlohmann::json;
namespace fs = std::filesystem;

TEST(Storage, LowDiskRefusesUploadsAndFailsReadyz) {
  // No test machine has a petabyte free: every upload is "below the minimum".
  auto s = with_double("lowdisk", "slow", {"--min-free-mb", "1000000000"}, "1");
  auto c = s->client();
  auto r = submit(c, read_bytes(shared_data("gltf/Box.glb")), "model/gltf-binary");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 503);
  EXPECT_FALSE(r->get_header_value("Retry-After").empty());
  EXPECT_EQ(r->get_header_value("Content-Type"), "application/problem+json");
  EXPECT_NE(json::parse(r->body)["type"].get<std::string>().find("insufficient-storage"), std::string::npos);
  auto ready = c.Get("/readyz");
  ASSERT_TRUE(ready);
  EXPECT_EQ(ready->status, 503);
  EXPECT_EQ(json::parse(ready->body)["checks"]["disk_space"], false) << ready->body;
  EXPECT_EQ(c.Get("/healthz")->status, 200);
  // With the default minimum the same server directory is ready.
  auto ok = with_double("lowdisk-ok", "slow", {}, "1");
  auto c2 = ok->client();
  auto ready2 = c2.Get("/readyz");
  EXPECT_EQ(json::parse(ready2->body)["checks"]["disk_space"], true) << ready2->body;
}

TEST(Storage, FullDiskIsStorageUnavailable) {
  using namespace soupuv::server;
  // /dev/full answers every write with ENOSPC.
  BoundedFileWriter w("/dev/full", 1 << 20);
  std::string bytes(65536, 'x');
  EXPECT_THROW(w.write(bytes.data(), bytes.size()), StorageUnavailable);
}

TEST(Storage, StaleTempFilesAreSwept) {
  using namespace soupuv::server;
  fs::path root = fresh_dir("sweep-temp");
  DataDir data(root);
  const std::string id = new_job_id();
  fs::create_directories(data.job(id) / "work");
  auto touch = [](const fs::path& p, bool old) {
    std::ofstream(p) << "x";
    if (old) fs::last_write_time(p, fs::file_time_type::clock::now() - std::chrono::hours(3));
  };
  touch(data.cache() / "ab.bin.tmp.1234.0", true);          // killed worker's cache write
  touch(data.cache() / "cd.bin.tmp.1234.1", false);         // a write in progress
  touch(data.cache() / "ef.bin", true);                      // a cache entry
  touch(data.job(id) / "work" / "diagnostics.json.tmp", true);
  touch(data.job(id) / "result.glb", true);
  EXPECT_EQ(sweep_stale_temp_files(root, std::chrono::hours(1)), 2);
  EXPECT_FALSE(fs::exists(data.cache() / "ab.bin.tmp.1234.0"));
  EXPECT_TRUE(fs::exists(data.cache() / "cd.bin.tmp.1234.1"));
  EXPECT_TRUE(fs::exists(data.cache() / "ef.bin"));
  EXPECT_FALSE(fs::exists(data.job(id) / "work" / "diagnostics.json.tmp"));
  EXPECT_TRUE(fs::exists(data.job(id) / "result.glb"));
}

namespace {

using namespace soupuv::server;

// A job store whose writes fail while `broken` is set (a full disk, an I/O
// error), as SQLite's do: by throwing StorageUnavailable.
class BrokenStore final : public JobStore {
 public:
  explicit BrokenStore(std::unique_ptr<JobStore> real) : real_(std::move(real)) {}
  std::atomic<bool> broken{false};

  std::optional<Job> create_or_get_by_key(const Job& j) override { return real_->create_or_get_by_key(j); }
  std::optional<Job> get(const std::string& id) override { return real_->get(id); }
  JobPage list(std::optional<JobState> s, int limit, const std::string& cursor,
               const std::optional<std::string>& tenant) override {
    return real_->list(s, limit, cursor, tenant);
  }
  void mark_running(const std::string& id, double at) override { check(); real_->mark_running(id, at); }
  void requeue(const std::string& id) override { check(); real_->requeue(id); }
  void update_progress(const std::string& id, const std::string& stage, double f, const json& ss) override {
    check();
    real_->update_progress(id, stage, f, ss);
  }
  void finish(const std::string& id, JobState st, const std::optional<JobError>& e,
              const std::vector<std::string>& outs, int attempt, double at) override {
    check();
    real_->finish(id, st, e, outs, attempt, at);
  }
  void request_cancel(const std::string& id) override { check(); real_->request_cancel(id); }
  void remove(const std::string& id) override { check(); real_->remove(id); }
  std::vector<Job> unfinished() override { return real_->unfinished(); }
  std::vector<std::string> finished_before(double t) override { return real_->finished_before(t); }
  std::map<std::string, int64_t> count_by_state() override { return real_->count_by_state(); }

 private:
  void check() {
    if (broken) throw StorageUnavailable("disk I/O error (test)");
  }
  std::unique_ptr<JobStore> real_;
};

std::string add_job(JobStore& store, const DataDir& data) {
  Job j;
  j.id = new_job_id();
  j.created_at = now_seconds();
  j.input_file = "input.glb";
  j.content_type = "model/gltf-binary";
  fs::create_directories(data.job(j.id));
  std::ofstream(data.job(j.id) / "input.glb") << "glTF";
  store.create_or_get_by_key(j);
  return j.id;
}

JobState wait_for(JobStore& store, const std::string& id, JobState want, double seconds) {
  auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  JobState st = JobState::queued;
  while (std::chrono::steady_clock::now() < deadline) {
    st = store.get(id)->state;
    if (st == want) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return st;
}

}  // namespace

TEST(Storage, FailingJobStoreNeverTerminatesTheSupervisor) {
  fs::path root = fresh_dir("broken-store");
  DataDir data(root);
  BrokenStore store(open_sqlite_job_store(data.database().string()));
  Config config;
  config.workers = 1;
  config.job_timeout_s = 20;
  config.worker_env = {"SOUPUV_TEST_WORKER_MODE", "SOUPUV_TEST_WORKER_SECONDS"};
  Metrics metrics;
  // The worker double reads its mode from the environment it inherits.
  setenv("SOUPUV_TEST_WORKER_MODE", "slow", 1);
  setenv("SOUPUV_TEST_WORKER_SECONDS", "0", 1);
  auto blobs = open_file_blob_store(data);
  Scheduler scheduler(config, SOUPUV_WORKER_DOUBLE, probe_worker(SOUPUV_WORKER_DOUBLE), store, data, metrics,
                      *blobs);
  scheduler.start();

  // Every write fails: the job cannot even be marked running. The thread
  // must survive (before: the error path's own write threw -> std::terminate).
  store.broken = true;
  const std::string lost = add_job(store, data);
  ASSERT_EQ(scheduler.enqueue(lost), Scheduler::Enqueue::accepted);
  std::this_thread::sleep_for(std::chrono::seconds(5));  // past the retries
  EXPECT_FALSE(is_finished(store.get(lost)->state));     // left for the next start

  // The disk comes back: the same worker thread runs the next job to the end.
  store.broken = false;
  const std::string next = add_job(store, data);
  ASSERT_EQ(scheduler.enqueue(next), Scheduler::Enqueue::accepted);
  EXPECT_EQ(wait_for(store, next, JobState::succeeded, 20), JobState::succeeded);

  // A store that fails for a moment while a job finishes: the finish is retried.
  const std::string flaky = add_job(store, data);
  setenv("SOUPUV_TEST_WORKER_SECONDS", "2", 1);
  ASSERT_EQ(scheduler.enqueue(flaky), Scheduler::Enqueue::accepted);
  ASSERT_EQ(wait_for(store, flaky, JobState::running, 10), JobState::running);
  store.broken = true;
  std::this_thread::sleep_for(std::chrono::milliseconds(2500));  // the worker ends meanwhile
  store.broken = false;
  EXPECT_EQ(wait_for(store, flaky, JobState::succeeded, 10), JobState::succeeded);
  scheduler.stop();
}
