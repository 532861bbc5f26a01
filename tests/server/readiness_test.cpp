// Deploy files that work (issue 21, item 6): a worker whose capabilities
// cannot be read (its `capabilities --json` says nothing, e.g. the probe could not run)
// makes /readyz fail instead of every job silently running without progress,
// cache or parameters.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "harness.h"

using namespace soupuv::test;
using nlohmann::json;

TEST(Readiness, UnknownWorkerCapabilitiesAreNotReady) {
  // A worker that prints nothing for `capabilities --json`: no flags are known.
  const auto dir = fresh_dir("ready-blind");
  const auto silent = dir / "silent-worker.sh";
  std::ofstream(silent) << "#!/bin/sh\nexit 0\n";
  std::filesystem::permissions(silent, std::filesystem::perms::owner_all);
  soupuv::test::ServerProcess blind(dir / "data", {"--worker-bin", silent.string()});
  auto c = blind.client();
  auto r = c.Get("/readyz");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 503) << r->body;
  EXPECT_EQ(json::parse(r->body)["checks"]["worker_capabilities"], false) << r->body;
  EXPECT_EQ(c.Get("/healthz")->status, 200);  // alive, just not ready

  auto s = with_double("ready-double", "slow", {}, "1");
  auto c2 = s->client();
  auto ok = c2.Get("/readyz");
  EXPECT_EQ(ok->status, 200) << ok->body;
  EXPECT_EQ(json::parse(ok->body)["checks"]["worker_capabilities"], true);
}
