// Unit tests for the session-2 server pieces: the in-memory job snapshot
// (against its slow twin, the SQLite store read directly), the field-cache
// pruner, and seam-hint validation.
#include <gtest/gtest.h>

#include <sys/stat.h>

#include <fstream>

#include "harness.h"
#include "test_job.h"
#include "soupuv/server/cache_prune.h"
#include "soupuv/server/files.h"
#include "soupuv/server/job_store.h"
#include "soupuv/server/params.h"

using namespace soupuv::server;
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

Job new_job(int i) { return soupuv::test::upload_job("h" + std::to_string(i), 0); }

// Everything to_json shows, so "same JSON" means "a client cannot tell".
void expect_same(const std::optional<Job>& a, const std::optional<Job>& b) {
  ASSERT_EQ(a.has_value(), b.has_value());
  if (!a) return;
  EXPECT_EQ(to_json(*a).dump(), to_json(*b).dump());
  EXPECT_EQ(a->cancel_requested, b->cancel_requested);
  EXPECT_EQ(a->attempts, b->attempts);
}

}  // namespace

TEST(SnapshotJobStore, ReadsMatchTheDatabaseAfterEveryWriteAndAcrossRestarts) {
  fs::path dir = soupuv::test::fresh_dir("snapshot");
  const std::string db = (dir / "jobs.sqlite").string();
  std::vector<std::string> ids;
  {
    auto snap = with_memory_snapshot(open_sqlite_job_store(db));
    auto direct = open_sqlite_job_store(db);  // a second connection: the slow twin
    for (int i = 0; i < 4; ++i) ids.push_back(snap->create_or_get_by_key(new_job(i))->id);
    snap->mark_running(ids[0], now_seconds());
    snap->update_progress(ids[0], "charge", 0.25, {{"load", 0.1}});
    expect_same(snap->get(ids[0]), direct->get(ids[0]));
    EXPECT_EQ(snap->get(ids[0])->stage, "charge");
    // A progress update for a job that is no longer running changes nothing,
    // in the database and so in the snapshot.
    snap->finish(ids[1], JobState::failed, JobError{"invalid_input", 400, "bad"}, {}, 0, now_seconds());
    snap->update_progress(ids[1], "trace", 0.5, json::object());
    expect_same(snap->get(ids[1]), direct->get(ids[1]));
    EXPECT_EQ(snap->get(ids[1])->stage, "");
    snap->request_cancel(ids[2]);
    expect_same(snap->get(ids[2]), direct->get(ids[2]));
    EXPECT_TRUE(snap->get(ids[2])->cancel_requested);
    snap->remove(ids[3]);
    EXPECT_FALSE(snap->get(ids[3]));
    EXPECT_FALSE(direct->get(ids[3]));
    EXPECT_EQ(snap->count_by_state(), direct->count_by_state());
  }
  // A new process loads every row: the snapshot survives a restart.
  auto snap = with_memory_snapshot(open_sqlite_job_store(db));
  auto direct = open_sqlite_job_store(db);
  for (const auto& id : ids) expect_same(snap->get(id), direct->get(id));
  EXPECT_EQ(snap->count_by_state(), direct->count_by_state());
  EXPECT_EQ(snap->count_by_state()["running"], 1);
}

TEST(CachePrune, RemovesLeastRecentlyUsedEntriesDownToTheBudget) {
  fs::path dir = soupuv::test::fresh_dir("cache-prune");
  fs::create_directories(dir / "ab");
  fs::create_directories(dir / "cd");
  auto make = [&](const fs::path& p, size_t bytes, int age_s) {
    std::ofstream(p, std::ios::binary) << std::string(bytes, 'x');
    timespec times[2];
    clock_gettime(CLOCK_REALTIME, &times[0]);
    times[0].tv_sec -= age_s;
    times[1] = times[0];
    ASSERT_EQ(utimensat(AT_FDCWD, p.c_str(), times, 0), 0);
  };
  make(dir / "ab" / "old.bin", 4000, 300);
  make(dir / "cd" / "middle.bin", 4000, 200);
  make(dir / "ab" / "new.bin", 4000, 100);
  make(dir / "ab" / "writing.tmp", 50000, 1000);  // not an entry: never touched

  auto none = prune_cache(dir, 20000);
  EXPECT_EQ(none.files_removed, 0);
  EXPECT_EQ(none.bytes_before, 12000);

  auto r = prune_cache(dir, 8000);
  EXPECT_EQ(r.files_removed, 1);
  EXPECT_EQ(r.bytes_after, 8000);
  EXPECT_FALSE(fs::exists(dir / "ab" / "old.bin"));
  EXPECT_TRUE(fs::exists(dir / "cd" / "middle.bin"));
  EXPECT_TRUE(fs::exists(dir / "ab" / "new.bin"));
  EXPECT_TRUE(fs::exists(dir / "ab" / "writing.tmp"));

  auto all = prune_cache(dir, 0);
  EXPECT_EQ(all.files_removed, 2);
  EXPECT_EQ(all.bytes_after, 0);
  EXPECT_EQ(prune_cache(dir / "missing", 0).bytes_before, 0);  // no directory yet: nothing to do
}

TEST(Params, SeamHintsValidatedAndLeftToTheScheduler) {
  WorkerCapabilities caps;
  caps.flags = {"--method", "--seam-hints"};
  json out;
  const json good = json::array({json::array({{0, 0, 0}, {1, 0.5, -2}}), json::array({{1, 1, 1}, {2, 2, 2}, {3, 3, 3}})});
  EXPECT_FALSE(validate_params({{"seam_hints", good}}, caps, out));
  EXPECT_EQ(out["seam_hints"], good);
  EXPECT_EQ(out["method"], "field") << "the API's default is the product's method";
  // The hints travel as a file (written by the scheduler), not as flags.
  EXPECT_EQ(params_to_flags(out, caps), (std::vector<std::string>{"--method", "field"}));

  EXPECT_TRUE(validate_params({{"seam_hints", 1}}, caps, out));
  EXPECT_TRUE(validate_params({{"seam_hints", "[[[0,0,0],[1,1,1]]]"}}, caps, out));  // a string, not JSON
  EXPECT_TRUE(validate_params({{"seam_hints", json::array({json::array({{0, 0, 0}})})}}, caps, out));  // 1 point
  EXPECT_TRUE(validate_params({{"seam_hints", json::array({json::array({{0, 0}, {1, 1}})})}}, caps, out));
  EXPECT_TRUE(validate_params({{"seam_hints", json::array({json::array({{0, 0, "x"}, {1, 1, 1}})})}}, caps, out));
  json inf = json::array({json::array({{0, 0, 0}, {1, 1, 1}})});
  inf[0][1][2] = std::numeric_limits<double>::infinity();
  EXPECT_TRUE(validate_params({{"seam_hints", inf}}, caps, out));
  json many_lines = json::array();
  for (size_t i = 0; i <= kMaxSeamHintLines; ++i) many_lines.push_back(json::array({{0, 0, 0}, {1, 1, 1}}));
  auto e = validate_params({{"seam_hints", many_lines}}, caps, out);
  EXPECT_NE(e.detail.find("polylines"), std::string::npos) << e.detail;
  json long_line = json::array();
  for (size_t i = 0; i <= kMaxSeamHintPoints; ++i) long_line.push_back({double(i), 0, 0});
  e = validate_params({{"seam_hints", json::array({long_line})}}, caps, out);
  EXPECT_NE(e.detail.find("points"), std::string::npos) << e.detail;
  // A CLI without --seam-hints: refused, not ignored.
  WorkerCapabilities old_cli;
  old_cli.flags = {"--method"};
  EXPECT_TRUE(validate_params({{"seam_hints", good}}, old_cli, out));
}
