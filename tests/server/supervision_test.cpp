// Worker supervision: timeout, crash, cancel, a worker that ignores SIGTERM,
// queue capacity with Retry-After. These use worker_double.sh (a stand-in that
// speaks the CLI's protocol and sleeps), because real mapping jobs finish too
// fast to be caught mid-run reliably. The restart test uses the real CLI.
#include <gtest/gtest.h>

#include <signal.h>

#include <chrono>
#include <fstream>

#include "harness.h"

using namespace soupuv::test;
using nlohmann::json;
namespace fs = std::filesystem;


TEST(Supervision, WallClockTimeoutFailsTheJobWithAReason) {
  auto s = with_double("timeout", "slow", {"--job-timeout", "2"});
  auto c = s->client();
  std::string id = submit_box(c);
  ASSERT_FALSE(id.empty());
  // The worker's progress lines reach the job (stage "wait" from the double).
  json running;
  for (int i = 0; i < 100; ++i) {
    running = wait_state(c, id, "running");
    if (running.value("stage", "") == "wait") break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  EXPECT_EQ(running["stage"], "wait") << running.dump();
  auto done = wait_finished(c, id, 20);
  EXPECT_EQ(done["state"], "failed");
  EXPECT_EQ(done["error"]["code"], "timeout") << done.dump();
  EXPECT_EQ(c.Get("/healthz")->status, 200);
}

TEST(Supervision, CrashFailsOneJobOnly) {
  auto s = with_double("crash", "crash");
  auto c = s->client();
  std::string id = submit_box(c);
  auto done = wait_finished(c, id, 20);
  EXPECT_EQ(done["state"], "failed");
  EXPECT_EQ(done["error"]["code"], "crashed") << done.dump();
  auto r = c.Get(("/v1/jobs/" + id + "/result").c_str());
  EXPECT_EQ(r->status, 409);
}

TEST(Supervision, WorkerErrorCarriesTheCliReason) {
  auto s = with_double("fail", "fail");
  auto c = s->client();
  auto done = wait_finished(c, submit_box(c), 20);
  EXPECT_EQ(done["state"], "failed");
  EXPECT_EQ(done["error"]["code"], "invalid_input");
  EXPECT_EQ(done["error"]["status"], 400);
  EXPECT_EQ(done["error"]["detail"], "test double refuses this input");
}

TEST(Supervision, CancelQueuedAndRunning) {
  auto s = with_double("cancel", "slow", {"--workers", "1"});
  auto c = s->client();
  std::string first = submit_box(c), second = submit_box(c);
  wait_state(c, first, "running");
  auto r2 = c.Post(("/v1/jobs/" + second + ":cancel").c_str());
  EXPECT_EQ(r2->status / 100, 2);  // a queued job is canceled at once (200) or as the worker sees it (202)
  EXPECT_EQ(wait_state(c, second, "canceled", 5)["state"], "canceled");
  auto r1 = c.Post(("/v1/jobs/" + first + ":cancel").c_str());
  EXPECT_EQ(r1->status, 202);
  auto t0 = std::chrono::steady_clock::now();
  EXPECT_EQ(wait_state(c, first, "canceled", 10)["state"], "canceled");
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 5.0);
}

TEST(Supervision, WorkerIgnoringSigtermIsKilled) {
  auto s = with_double("hang", "hang", {"--job-timeout", "1"});
  auto c = s->client();
  auto done = wait_finished(c, submit_box(c), 20);  // 1 s timeout + 5 s grace
  EXPECT_EQ(done["state"], "failed");
  EXPECT_EQ(done["error"]["code"], "timeout");
}

TEST(Supervision, FullQueueAnswers429WithRetryAfter) {
  auto s = with_double("full", "slow", {"--workers", "1", "--queue-capacity", "2"});
  auto c = s->client();
  std::string running = submit_box(c);
  wait_state(c, running, "running");
  EXPECT_FALSE(submit_box(c).empty());
  EXPECT_FALSE(submit_box(c).empty());
  auto r = submit(c, read_bytes(shared_data("gltf/Box.glb")), "model/gltf-binary");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 429);
  EXPECT_FALSE(r->get_header_value("Retry-After").empty());
  EXPECT_EQ(r->get_header_value("Content-Type"), "application/problem+json");
  auto m = c.Get("/metrics");
  EXPECT_NE(m->body.find("soupuv_queue_depth 2"), std::string::npos) << m->body;
  EXPECT_NE(m->body.find("soupuv_workers_busy 1"), std::string::npos);
  // Status stays fast while every worker is busy.
  auto t0 = std::chrono::steady_clock::now();
  for (int i = 0; i < 50; ++i) ASSERT_EQ(c.Get(("/v1/jobs/" + running).c_str())->status, 200);
  double per = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() / 50;
  EXPECT_LT(per, 0.05);
}

TEST(Auth, TokensOnAndOff) {
  fs::path dir = fresh_dir("auth");
  const std::string token = "s3cret-token-1-0123456789abcdefghij";
  std::ofstream(dir / "tokens") << "# api tokens\n" << token << "\n";
  auto s = with_double("auth-server", "slow", {"--tokens-file", (dir / "tokens").string()}, "1");
  auto c = s->client();
  auto none = submit(c, read_bytes(shared_data("gltf/Box.glb")), "model/gltf-binary");
  EXPECT_EQ(none->status, 401);
  EXPECT_EQ(none->get_header_value("WWW-Authenticate").rfind("Bearer", 0), 0u);
  auto wrong = c.Get("/v1/jobs", {{"Authorization", "Bearer nope"}});
  EXPECT_EQ(wrong->status, 401);
  EXPECT_EQ(wrong->get_header_value("Content-Type"), "application/problem+json");
  auto ok = c.Get("/v1/jobs", {{"Authorization", "Bearer " + token}});
  EXPECT_EQ(ok->status, 200);
  auto sub = submit(c, read_bytes(shared_data("gltf/Box.glb")), "model/gltf-binary", "",
                    {{"Authorization", "Bearer " + token}});
  EXPECT_EQ(sub->status, 202);
  EXPECT_EQ(c.Get("/healthz")->status, 200);  // operations stay open
  EXPECT_EQ(c.Get("/v1/openapi.yaml")->status, 200);
  // Without a tokens file (loopback) the API is open.
  auto open = with_double("auth-off", "slow", {}, "1");
  auto c2 = open->client();
  EXPECT_EQ(c2.Get("/v1/jobs")->status, 200);
}

TEST(Cors, OnlyConfiguredOrigins) {
  auto s = with_double("cors", "slow", {"--cors-origins", "https://app.example"}, "1");
  auto c = s->client();
  auto ok = c.Get("/v1/jobs", {{"Origin", "https://app.example"}});
  EXPECT_EQ(ok->get_header_value("Access-Control-Allow-Origin"), "https://app.example");
  auto other = c.Get("/v1/jobs", {{"Origin", "https://evil.example"}});
  EXPECT_FALSE(other->has_header("Access-Control-Allow-Origin"));
  auto pre = c.Options("/v1/jobs", {{"Origin", "https://app.example"}, {"Access-Control-Request-Method", "POST"}});
  EXPECT_EQ(pre->status, 204);
  EXPECT_NE(pre->get_header_value("Access-Control-Allow-Methods").find("POST"), std::string::npos);
}

TEST(Recovery, SigkillWithJobsQueuedAndRunningThenEveryJobFinishes) {
  if (!cli_available()) GTEST_SKIP() << "needs the real soupuv CLI";
  fs::path data = fresh_dir("recovery");
  // Uploads are not re-inspected here, so that all four are queued while the
  // first one still runs.
  std::vector<std::string> args = {"--worker-bin", SOUPUV_CLI_BIN, "--workers", "1", "--threads", "1",
                                   "--validate-uploads", "false"};
  std::vector<std::string> ids;
  {
    ServerProcess s(data, args);
    auto c = s.client();
    std::string bunny = read_bytes(shared_data("soups/stanford-bunny-soup.glb"));
    for (int i = 0; i < 4; ++i) {
      auto r = submit(c, bunny, "model/gltf-binary", "?method=box&texture_size=" + std::to_string(64 << i));
      ASSERT_TRUE(r);
      ASSERT_EQ(r->status, 202) << r->body;
      ids.push_back(json::parse(r->body)["id"]);
    }
    auto running = wait_state(c, ids[0], "running", 20);
    ASSERT_EQ(running["state"], "running");
    s.kill_hard();
  }
  ServerProcess again(data, args);
  auto c = again.client();
  EXPECT_NE(again.log().find("\"msg\":\"job recovered\""), std::string::npos);
  int rerun = 0;
  for (const auto& id : ids) {
    auto done = wait_finished(c, id, 90);
    EXPECT_EQ(done["state"], "succeeded") << done.dump();
    if (done["attempts"].get<int>() > 1) ++rerun;
    auto r = c.Get(("/v1/jobs/" + id + "/result").c_str());
    ASSERT_TRUE(r);
    EXPECT_EQ(r->status, 200);
    EXPECT_EQ(r->body.substr(0, 4), "glTF");
  }
  EXPECT_GE(rerun, 1) << "the job running at the kill was not run again";
  auto list = json::parse(c.Get("/v1/jobs?limit=100")->body);
  EXPECT_EQ(list["jobs"].size(), ids.size()) << "jobs lost or duplicated";
}
