// Untrusted models are parsed in a sandbox (issue 21, item 2): a worker double
// that does what a hostile parser would — read the tokens file, the job
// database and the server's environment, write outside its scratch
// directory, flood stdout — is denied each time, and its job fails with a
// reason. Workers get a minimal environment. Needs Landlock in the kernel.
#include <gtest/gtest.h>

#include <fstream>

#include "harness.h"
#include "soupuv/server/sandbox.h"

using namespace soupuv::test;
using nlohmann::json;
namespace fs = std::filesystem;

TEST(Sandbox, HostileWorkerIsDeniedEverythingAndItsJobFails) {
  if (soupuv::server::landlock_abi() == 0) GTEST_SKIP() << "this kernel has no Landlock";
  fs::path dir = fresh_dir("sandbox");
  const std::string token = "sandbox-secret-token-0123456789abcdefghij";
  std::ofstream(dir / "tokens") << "alice " << token << "\n";
  const fs::path data = dir / "data";
  const fs::path outside = data / "escaped.txt";
  ServerProcess s(data,
                  {"--worker-bin", SOUPUV_WORKER_DOUBLE, "--validate-uploads", "false", "--worker-env", kDoubleEnv,
                   "--tokens-file", (dir / "tokens").string(), "--worker-sandbox", "landlock"},
                  {"SOUPUV_TEST_WORKER_MODE=escape",
                   "SOUPUV_TEST_ESCAPE_READ=" + (dir / "tokens").string() + ":" + (data / "jobs.sqlite").string(),
                   "SOUPUV_TEST_ESCAPE_WRITE=" + outside.string(), "SERVER_ONLY_SECRET=hunter2-server-env"});
  auto c = s.client();
  const httplib::Headers auth = {{"Authorization", "Bearer " + token}};
  const std::string id = submit_box(c, auth);
  ASSERT_FALSE(id.empty());
  json done;
  for (int i = 0; i < 400; ++i) {
    done = json::parse(c.Get(("/v1/jobs/" + id).c_str(), auth)->body);
    if (done["state"] == "failed" || done["state"] == "succeeded") break;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  // The flood ends the job, with a reason.
  EXPECT_EQ(done["state"], "failed") << done.dump();
  EXPECT_EQ(done["error"]["code"], "output_limit") << done.dump();
  EXPECT_EQ(done["attempts"], 1);

  const std::string log = read_bytes(data / "jobs" / id / "worker.log");
  ASSERT_FALSE(log.empty());
  EXPECT_EQ(log.find(token), std::string::npos) << "the worker read the tokens file";
  EXPECT_EQ(log.find("SQLite format 3"), std::string::npos) << "the worker read the job database";
  EXPECT_EQ(log.find("hunter2-server-env"), std::string::npos) << "the server's environment reached the worker";
  EXPECT_NE(log.find("escape: denied read " + (dir / "tokens").string()), std::string::npos) << log;
  EXPECT_NE(log.find("escape: denied read " + (data / "jobs.sqlite").string()), std::string::npos) << log;
  EXPECT_NE(log.find("escape: denied read /proc/"), std::string::npos) << log;
  EXPECT_NE(log.find("escape: denied write"), std::string::npos) << log;
  EXPECT_FALSE(fs::exists(outside));
  // No capabilities, even when the server runs as root (as in CI).
  EXPECT_NE(log.find("escape: CapEff:\t0000000000000000"), std::string::npos) << log;
  EXPECT_NE(log.find("escape: CapBnd:\t0000000000000000"), std::string::npos) << log;
  // Its environment: the minimal set and what --worker-env names, nothing else.
  const std::string env = log.substr(log.find("escape: environment follows"));
  EXPECT_NE(env.find("HOME=" + (data / "jobs" / id / "work").string()), std::string::npos) << env;
  EXPECT_NE(env.find("OMP_NUM_THREADS="), std::string::npos) << env;
  EXPECT_NE(s.log().find("\"worker_sandbox\":\"landlock\""), std::string::npos);
}

TEST(Sandbox, RealWorkerStillMapsInsideTheSandbox) {
  if (soupuv::server::landlock_abi() == 0) GTEST_SKIP() << "this kernel has no Landlock";
  if (!cli_available()) GTEST_SKIP() << "needs the real soupuv CLI";
  // Upload check (`soupuv inspect`) and the job itself both run confined.
  ServerProcess s(fresh_dir("sandbox-real"),
                  {"--worker-bin", SOUPUV_CLI_BIN, "--worker-sandbox", "landlock", "--threads", "1"});
  auto c = s.client();
  auto r = submit(c, read_bytes(shared_data("gltf/Box.glb")), "model/gltf-binary", "?method=box&texture_size=64");
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 202) << r->body;
  auto done = wait_finished(c, json::parse(r->body)["id"], 60);
  EXPECT_EQ(done["state"], "succeeded") << done.dump();
  // A bad model is still refused synchronously by the confined inspect.
  auto bad = submit(c, "glTF-not-really-a-model-at-all", "model/gltf-binary");
  ASSERT_TRUE(bad);
  EXPECT_EQ(bad->status / 100, 4) << bad->body;
}
