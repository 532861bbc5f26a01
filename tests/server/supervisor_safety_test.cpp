// The supervisor never loses a child (issue 21, item 3): run_process kills and
// reaps its worker on every exit path, including an exception thrown by the
// line callback; a malformed progress line is ignored, not fatal; a job whose
// worker crashes, or that is lost with the server, is run again up to
// --max-attempts and then failed with a reason.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/wait.h>

#include <atomic>
#include <chrono>
#include <stdexcept>

#include "harness.h"
#include "soupuv/server/worker_process.h"

using namespace soupuv::test;
using nlohmann::json;
namespace fs = std::filesystem;

namespace {

bool process_gone(pid_t pid) { return ::kill(pid, 0) != 0 && errno == ESRCH; }

}  // namespace

TEST(RunProcess, CallbackExceptionKillsAndReapsTheChild) {
  using namespace soupuv::server;
  // The child names itself, then would live for a minute.
  std::vector<std::string> argv = {"/bin/sh", "-c", "echo pid $$ >&2; exec sleep 60"};
  std::atomic<bool> never{false};
  pid_t child = 0;
  auto t0 = std::chrono::steady_clock::now();
  EXPECT_THROW(run_process(argv, {}, ProcessLimits{}, never,
                           [&](const std::string& line) {
                             if (line.rfind("pid ", 0) == 0) child = std::stoi(line.substr(4));
                             throw std::runtime_error("store write failed");
                           }),
               std::runtime_error);
  ASSERT_GT(child, 0);
  // Gone and reaped (a zombie still answers kill(pid, 0)) when the exception
  // reaches the caller, not 60 s later.
  EXPECT_TRUE(process_gone(child)) << "worker " << child << " outlived its supervisor";
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 10.0);
}

TEST(Supervision, MalformedProgressLineIsIgnored) {
  auto s = with_double("badprogress", "badprogress", {}, "1");
  auto c = s->client();
  std::string id = submit_box(c);
  ASSERT_FALSE(id.empty());
  auto done = wait_finished(c, id, 20);
  EXPECT_EQ(done["state"], "succeeded") << done.dump();
  EXPECT_EQ(done["attempts"], 1);
}

TEST(Supervision, CrashedJobIsRetriedUpToTheAttemptLimit) {
  auto s = with_double("crash-retry", "crash", {"--max-attempts", "3"});
  auto c = s->client();
  std::string id = submit_box(c);
  ASSERT_FALSE(id.empty());
  auto done = wait_finished(c, id, 30);
  EXPECT_EQ(done["state"], "failed") << done.dump();
  EXPECT_EQ(done["attempts"], 3) << done.dump();
  EXPECT_EQ(done["error"]["code"], "crashed");
  EXPECT_NE(done["error"]["detail"].get<std::string>().find("3 attempts"), std::string::npos) << done.dump();
}

TEST(Recovery, JobLostAtEveryRestartFailsAtTheAttemptLimit) {
  // A job that takes the server down with it each time (here: SIGKILL of the
  // server while it runs) must not loop forever across restarts.
  fs::path data = fresh_dir("poison");
  std::vector<std::string> args = {"--worker-bin", SOUPUV_WORKER_DOUBLE, "--validate-uploads", "false",
                                   "--max-attempts", "2", "--worker-env", kDoubleEnv};
  std::vector<std::string> env = {"SOUPUV_TEST_WORKER_MODE=slow", "SOUPUV_TEST_WORKER_SECONDS=60"};
  std::string id;
  {
    ServerProcess s(data, args, env);
    auto c = s.client();
    id = submit_box(c);
    ASSERT_FALSE(id.empty());
    ASSERT_EQ(wait_state(c, id, "running")["state"], "running");
    s.kill_hard();
  }
  {
    ServerProcess s(data, args, env);
    auto c = s.client();
    // The row still says running from before the kill: wait for the re-run.
    json j;
    for (int i = 0; i < 400; ++i) {
      j = wait_state(c, id, "running");
      if (j.value("attempts", 0) == 2) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(25));
    }
    ASSERT_EQ(j["state"], "running");
    ASSERT_EQ(j["attempts"], 2);
    s.kill_hard();
  }
  ServerProcess s(data, args, env);
  auto c = s.client();
  auto j = wait_finished(c, id, 10);
  EXPECT_EQ(j["state"], "failed") << j.dump();
  EXPECT_EQ(j["attempts"], 2);
  EXPECT_EQ(j["error"]["code"], "interrupted") << j.dump();
}
