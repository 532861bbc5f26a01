// End to end on the product's method: the real server, the real `soupuv map`
// worker, `method` left to the API default (field). Box.glb (12 triangles) at a
// coarse proxy resolution keeps each job at a few seconds.
//   - the default method is field and the job's diagnostics come from it;
//   - seam hints in the params reach the atlas (forced seam edges);
//   - two jobs on the same mesh with different offsets share the on-disk field
//     cache: the second reports cache hits (charges and lines do not depend on
//     the proxy offset).
#include <gtest/gtest.h>

#include "harness.h"

using namespace soupuv::test;
using nlohmann::json;

namespace {

#define REQUIRE_CLI() \
  if (!cli_available()) GTEST_SKIP() << "the soupuv CLI was not built; end-to-end tests need it"

class Field : public ::testing::Test {
 protected:
  void SetUp() override {
    REQUIRE_CLI();
    server_ = std::make_unique<ServerProcess>(fresh_dir("field"), std::vector<std::string>{
        "--worker-bin", SOUPUV_CLI_BIN, "--workers", "1", "--threads", "2"});
  }
  // Multipart with a params part, as the upload page and most clients send it.
  json run(const json& params) {
    auto c = server_->client();
    httplib::MultipartFormDataItems items = {
        {"file", read_bytes(shared_data("gltf/Box.glb")), "box.glb", "model/gltf-binary"},
        {"params", params.dump(), "", "application/json"},
    };
    auto r = c.Post("/v1/jobs", items);
    if (!r || r->status != 202) {
      ADD_FAILURE() << (r ? r->body : "no response");
      return json();
    }
    return wait_finished(c, json::parse(r->body)["id"], 120);
  }
  json diagnostics(const json& job) {
    auto c = server_->client();
    auto d = c.Get(("/v1/jobs/" + job["id"].get<std::string>() + "/diagnostics").c_str());
    if (!d || d->status != 200) return json();
    return json::parse(d->body, nullptr, false);
  }
  std::unique_ptr<ServerProcess> server_;
};

}  // namespace

TEST_F(Field, DefaultMethodIsFieldEndToEnd) {
  auto c = server_->client();
  auto described = json::parse(c.Get("/v1/params")->body)["params"];
  for (const auto& p : described)
    if (p["name"] == "method") {
      EXPECT_EQ(p["default"], "field");
    }
  json done = run({{"resolution", 16}, {"debug_outputs", true}});
  ASSERT_EQ(done["state"], "succeeded") << done.dump();
  EXPECT_EQ(done["params"]["method"], "field");
  // The field pipeline's stages were reported while it ran (sub-stages such
  // as proxy/remeshing arrive as proxy__remeshing).
  for (const std::string stage : {"charge", "trace", "proxy", "atlas"}) {
    bool seen = false;
    for (const auto& [name, secs] : done["stage_seconds"].items()) seen = seen || name.rfind(stage, 0) == 0;
    EXPECT_TRUE(seen) << stage << " missing in " << done["stage_seconds"].dump();
  }
  json d = diagnostics(done);
  ASSERT_TRUE(d.is_object());
  EXPECT_EQ(d["soup"]["triangles"], 12);
  EXPECT_TRUE(d["charge"]["converged"].get<bool>()) << d["charge"].dump();
  EXPECT_GT(d["trace"]["lines"].get<int>(), 0);
  const std::string id = done["id"];
  auto glb = c.Get(("/v1/jobs/" + id + "/result").c_str());
  ASSERT_TRUE(glb);
  EXPECT_EQ(glb->body.substr(0, 4), "glTF");
  EXPECT_NE(glb->body.find("TEXCOORD_0"), std::string::npos);
  // Debug outputs of the field method are offered and served.
  for (const char* name : {"proxy.glb", "field-lines.glb", "uv-layout.png"}) {
    EXPECT_TRUE(done["links"].contains(name)) << done["links"].dump();
    auto f = c.Get(("/v1/jobs/" + id + "/" + name).c_str());
    ASSERT_TRUE(f);
    EXPECT_EQ(f->status, 200) << name;
  }
}

TEST_F(Field, SeamHintsReachTheAtlas) {
  json plain = run({{"resolution", 16}});
  ASSERT_EQ(plain["state"], "succeeded") << plain.dump();
  EXPECT_EQ(diagnostics(plain)["atlas"]["seam_edges"], 0);
  // The UV layout is served without debug outputs too (soupuv map --uv-layout).
  EXPECT_TRUE(plain["links"].contains("uv-layout.png")) << plain["links"].dump();
  // A diagonal over the top face of the unit box: the atlas must cut along it.
  json hints = json::array({json::array({{-0.5, 0.5, -0.5}, {0.5, 0.5, 0.5}})});
  json hinted = run({{"resolution", 16}, {"seam_hints", hints}});
  ASSERT_EQ(hinted["state"], "succeeded") << hinted.dump();
  EXPECT_EQ(hinted["params"]["seam_hints"], hints);
  EXPECT_GT(diagnostics(hinted)["atlas"]["seam_edges"].get<int>(), 0);
  // Refusals are synchronous problem+json, before any work.
  auto c = server_->client();
  std::string box = read_bytes(shared_data("gltf/Box.glb"));
  for (const char* bad : {"?seam_hints=1", "?seam_hints=%5B%5B%5B0,0,0%5D%5D%5D",  // one point
                          "?seam_hints=%5B%5B%5B0,0%5D,%5B1,1%5D%5D%5D",            // 2-D points
                          "?seam_hints=%5B%5B%5B0,0,0%5D,%5B1e999,0,0%5D%5D%5D"}) { // not finite
    auto r = submit(c, box, "model/gltf-binary", bad);
    ASSERT_TRUE(r);
    EXPECT_EQ(r->status, 400) << bad << ": " << r->body;
    EXPECT_EQ(r->get_header_value("Content-Type"), "application/problem+json");
  }
}

TEST_F(Field, SecondOffsetOnTheSameMeshHitsTheSharedFieldCache) {
  json first = run({{"resolution", 16}, {"offset", 0.05}});
  ASSERT_EQ(first["state"], "succeeded") << first.dump();
  json d1 = diagnostics(first);
  EXPECT_EQ(d1["cache"]["enabled"], true) << "workers get the server's cache directory";
  EXPECT_EQ(d1["cache"]["hits"], 0);
  json second = run({{"resolution", 16}, {"offset", 0.1}});
  ASSERT_EQ(second["state"], "succeeded") << second.dump();
  json d2 = diagnostics(second);
  // Charges and field lines come from the first job's run (another process).
  EXPECT_EQ(d2["cache"]["hits"], 2) << d2["cache"].dump();
  EXPECT_GT(d2["cache"]["store"]["disk_hits"].get<int>(), 0) << d2["cache"].dump();
  EXPECT_EQ(d2["charge"]["cached"], true);
  // The server counts them in /metrics.
  auto m = server_->client().Get("/metrics");
  ASSERT_TRUE(m);
  EXPECT_NE(m->body.find("soupuv_cache_hits_total 2"), std::string::npos) << m->body;
}
