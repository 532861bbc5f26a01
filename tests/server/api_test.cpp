// API v1 over a real socket, with the real soupuv CLI as worker: submit, poll,
// download, list, idempotency, every refusal as problem+json, the contract
// against proto/openapi.yaml. Tests of the server's plumbing ask for
// `method=box` explicitly (fast; they test the server, not the method); the
// tests named Field* run the product's default method on a small mesh.
#include <gtest/gtest.h>

#include <fstream>
#include <regex>
#include <set>

#include "harness.h"
#include "soupuv/server/app.h"

using namespace soupuv::test;
using nlohmann::json;
namespace fs = std::filesystem;

namespace {

#define REQUIRE_CLI() \
  if (!cli_available()) GTEST_SKIP() << "the soupuv CLI was not built; end-to-end tests need it"

void expect_problem(const httplib::Result& r, int status) {
  ASSERT_TRUE(r) << "no response";
  EXPECT_EQ(r->status, status) << r->body;
  EXPECT_EQ(r->get_header_value("Content-Type"), "application/problem+json") << r->body;
  auto p = json::parse(r->body, nullptr, false);
  ASSERT_TRUE(p.is_object()) << r->body;
  EXPECT_EQ(p["status"], status);
  EXPECT_TRUE(p["type"].is_string());
  EXPECT_TRUE(p["title"].is_string());
  EXPECT_TRUE(p["detail"].is_string());
}

// The (method, path) pairs of proto/openapi.yaml's `paths:` section. Our own
// file, in block style: paths at two spaces, methods at four.
std::set<std::pair<std::string, std::string>> spec_routes() {
  std::ifstream in(std::string(SOUPUV_SOURCE_DIR) + "/proto/openapi.yaml");
  std::set<std::pair<std::string, std::string>> out;
  std::string line, path;
  bool in_paths = false;
  static const std::regex path_re("^  (/\\S*):\\s*$"), method_re("^    (get|post|put|patch|delete):\\s*$");
  while (std::getline(in, line)) {
    if (line == "paths:") { in_paths = true; continue; }
    if (in_paths && !line.empty() && line[0] != ' ') break;
    std::smatch m;
    if (std::regex_match(line, m, path_re)) path = m[1];
    else if (std::regex_match(line, m, method_re)) out.insert({m[1], path});
  }
  return out;
}

class Api : public ::testing::Test {
 protected:
  void SetUp() override {
    REQUIRE_CLI();
    server_ = std::make_unique<ServerProcess>(fresh_dir("api"), std::vector<std::string>{
        "--worker-bin", SOUPUV_CLI_BIN, "--workers", "2", "--threads", "2"});
  }
  std::unique_ptr<ServerProcess> server_;
};

}  // namespace

TEST_F(Api, SubmitPollDownloadGlb) {
  auto c = server_->client();
  auto r = submit(c, read_bytes(shared_data("soups/spot-soup.glb")), "model/gltf-binary", "?method=box&texture_size=256");
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 202) << r->body;
  auto job = json::parse(r->body);
  std::string id = job["id"];
  EXPECT_EQ(r->get_header_value("Location"), "/v1/jobs/" + id);
  EXPECT_EQ(job["state"], "queued");
  EXPECT_EQ(job["params"]["texture_size"], 256);
  auto done = wait_finished(c, id);
  ASSERT_EQ(done["state"], "succeeded") << done.dump();
  EXPECT_GE(done["attempts"], 1);
  EXPECT_TRUE(done["stage_seconds"].is_object());
  EXPECT_FALSE(done["stage_seconds"].empty()) << "the worker's progress lines reached the store";
  auto glb = c.Get(("/v1/jobs/" + id + "/result").c_str());
  ASSERT_TRUE(glb);
  EXPECT_EQ(glb->status, 200);
  EXPECT_EQ(glb->get_header_value("Content-Type"), "model/gltf-binary");
  ASSERT_GT(glb->body.size(), 12u);
  EXPECT_EQ(glb->body.substr(0, 4), "glTF");
  EXPECT_NE(glb->body.find("TEXCOORD_0"), std::string::npos);
  auto diag = c.Get(("/v1/jobs/" + id + "/diagnostics").c_str());
  ASSERT_TRUE(diag);
  EXPECT_EQ(diag->status, 200);
  auto d = json::parse(diag->body, nullptr, false);
  ASSERT_TRUE(d.is_object());
  EXPECT_EQ(d["soup"]["triangles"], 5856);
  EXPECT_EQ(diag->body.find("test-tmp"), std::string::npos) << "diagnostics leak server paths";
  // Delete a finished job: its files go, then it is 404.
  auto del = c.Delete(("/v1/jobs/" + id).c_str());
  ASSERT_TRUE(del);
  EXPECT_EQ(del->status, 204);
  expect_problem(c.Get(("/v1/jobs/" + id).c_str()), 404);
}

TEST_F(Api, MultipartWithParamsAndDracoInput) {
  auto c = server_->client();
  httplib::MultipartFormDataItems items = {
      {"file", read_bytes(shared_data("drc/bunny_gltf.drc")), "bunny.drc", "application/octet-stream"},
      {"params", R"({"method":"box","texture_size":128})", "", "application/json"},
  };
  auto r = c.Post("/v1/jobs", items);
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 202) << r->body;
  auto job = json::parse(r->body);
  EXPECT_EQ(job["input"]["content_type"], "application/octet-stream");
  auto done = wait_finished(c, job["id"]);
  EXPECT_EQ(done["state"], "succeeded") << done.dump();
}

TEST_F(Api, ListPagingAndStateFilter) {
  auto c = server_->client();
  std::string box = read_bytes(shared_data("gltf/Box.glb"));
  std::set<std::string> ids;
  for (int i = 0; i < 5; ++i) {
    auto r = submit(c, box, "model/gltf-binary", "?method=box");
    ASSERT_TRUE(r);
    ASSERT_EQ(r->status, 202);
    ids.insert(json::parse(r->body)["id"].get<std::string>());
  }
  for (const auto& id : ids) EXPECT_EQ(wait_finished(c, id)["state"], "succeeded");
  std::set<std::string> seen;
  std::string cursor;
  for (int page = 0; page < 10; ++page) {
    auto r = c.Get(("/v1/jobs?limit=2&state=succeeded" + (cursor.empty() ? "" : "&cursor=" + cursor)).c_str());
    ASSERT_TRUE(r);
    ASSERT_EQ(r->status, 200);
    auto j = json::parse(r->body);
    EXPECT_LE(j["jobs"].size(), 2u);
    for (const auto& job : j["jobs"]) {
      EXPECT_EQ(job["state"], "succeeded");
      EXPECT_TRUE(seen.insert(job["id"].get<std::string>()).second) << "a job listed twice";
    }
    if (j["next_cursor"].is_null()) break;
    cursor = j["next_cursor"];
  }
  EXPECT_EQ(seen, ids);
  auto none = json::parse(c.Get("/v1/jobs?state=failed")->body);
  EXPECT_TRUE(none["jobs"].empty());
  expect_problem(c.Get("/v1/jobs?state=bogus"), 400);
  expect_problem(c.Get("/v1/jobs?limit=0"), 400);
  expect_problem(c.Get("/v1/jobs?cursor=abc"), 400);
}

TEST_F(Api, IdempotencyKey) {
  auto c = server_->client();
  std::string box = read_bytes(shared_data("gltf/Box.glb"));
  auto a = submit(c, box, "model/gltf-binary", "?method=box", {{"Idempotency-Key", "order-17"}});
  auto b = submit(c, box, "model/gltf-binary", "?method=box", {{"Idempotency-Key", "order-17"}});
  ASSERT_TRUE(a && b);
  ASSERT_EQ(a->status, 202);
  ASSERT_EQ(b->status, 202);
  EXPECT_EQ(json::parse(a->body)["id"], json::parse(b->body)["id"]);
  EXPECT_EQ(b->get_header_value("Idempotent-Replayed"), "true");
  // Same key, another request (other params): 422.
  expect_problem(submit(c, box, "model/gltf-binary", "?method=box&texture_size=64", {{"Idempotency-Key", "order-17"}}), 422);
  expect_problem(submit(c, box, "model/gltf-binary", "", {{"Idempotency-Key", "bad key with spaces"}}), 400);
  auto list = json::parse(c.Get("/v1/jobs?limit=100")->body);
  EXPECT_EQ(list["jobs"].size(), 1u) << "a retried submission made a second job";
}

TEST_F(Api, BadSharedInputsGiveProblemJsonAndServerKeepsServing) {
  auto c = server_->client();
  for (const auto& e : fs::directory_iterator(shared_data("bad"))) {
    std::string name = e.path().filename();
    if (name == "README.md") continue;
    std::string ct = e.path().extension() == ".gltf" ? "model/gltf+json"
                     : e.path().extension() == ".drc" ? "application/octet-stream" : "model/gltf-binary";
    auto r = submit(c, read_bytes(e.path()), ct, "?method=box");
    ASSERT_TRUE(r) << name;
    EXPECT_GE(r->status, 400) << name << ": " << r->body;
    EXPECT_LT(r->status, 500) << name << ": " << r->body;
    EXPECT_EQ(r->get_header_value("Content-Type"), "application/problem+json") << name;
    auto p = json::parse(r->body, nullptr, false);
    EXPECT_FALSE(p.value("detail", "").empty()) << name;
    if (name == "points-only.glb" || name == "point-cloud.drc") {
      EXPECT_EQ(r->status, 422) << name;
    }
    if (name == "external-uri.gltf") {
      EXPECT_NE(p.value("detail", "").find("external"), std::string::npos);
    }
    auto h = c.Get("/healthz");
    ASSERT_TRUE(h) << "server stopped answering after " << name;
    EXPECT_EQ(h->status, 200);
  }
  EXPECT_TRUE(json::parse(c.Get("/v1/jobs")->body)["jobs"].empty()) << "a refused upload left a job behind";
}

TEST_F(Api, ErrorPaths) {
  auto c = server_->client();
  std::string box = read_bytes(shared_data("gltf/Box.glb"));
  expect_problem(c.Get("/v1/jobs/jaaaaaaaaaaaaaaaaaaaaaaaaaa"), 404);
  expect_problem(c.Get("/v1/jobs/not-an-id"), 404);
  expect_problem(c.Get("/v1/jobs/jaaaaaaaaaaaaaaaaaaaaaaaaaa/result"), 404);
  expect_problem(c.Delete("/v1/jobs/jaaaaaaaaaaaaaaaaaaaaaaaaaa"), 404);
  expect_problem(c.Get("/no/such/route"), 404);
  expect_problem(submit(c, box, "text/plain"), 415);
  expect_problem(submit(c, box, "model/gltf-binary", "?method=magic"), 400);
  expect_problem(submit(c, box, "model/gltf-binary", "?steps=0"), 400);  // out of range
  // A parameter the worker's CLI lacks is refused, not ignored.
  auto params = json::parse(c.Get("/v1/params")->body)["params"];
  for (const auto& p : params)
    if (!p["supported"].get<bool>() && p["type"] == "boolean") {
      std::string query = "?";  // built in steps: GCC 12 warns (-Wrestrict) on "?" + string
      query += p["name"].get<std::string>();
      query += "=true";
      expect_problem(submit(c, box, "model/gltf-binary", query), 400);
    }
  expect_problem(submit(c, box, "model/gltf-binary", "?params=%7Bnope"), 400);
  expect_problem(submit(c, "", "model/gltf-binary"), 400);
  httplib::MultipartFormDataItems no_file = {{"params", "{}", "", "application/json"}};
  expect_problem(c.Post("/v1/jobs", no_file), 400);
  httplib::MultipartFormDataItems bad_part = {{"file", box, "a.glb", "model/gltf-binary"}, {"extra", "x", "", "text/plain"}};
  expect_problem(c.Post("/v1/jobs", bad_part), 400);
  // A real worker canceled mid-run: SIGTERM reaches the CLI's cancel flag.
  auto f = submit(c, read_bytes(shared_data("soups/stanford-bunny-soup.glb")), "model/gltf-binary", "?method=field");
  ASSERT_TRUE(f);
  ASSERT_EQ(f->status, 202) << f->body;
  std::string id = json::parse(f->body)["id"];
  for (int i = 0; i < 400; ++i) {
    if (json::parse(c.Get(("/v1/jobs/" + id).c_str())->body)["state"] != "queued") break;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  expect_problem(c.Get(("/v1/jobs/" + id + "/result").c_str()), 409);  // not finished
  auto cancel = c.Post(("/v1/jobs/" + id + ":cancel").c_str());
  ASSERT_TRUE(cancel);
  EXPECT_TRUE(cancel->status == 202 || cancel->status == 200 || cancel->status == 409) << cancel->body;
  auto done = wait_finished(c, id, 30);
  EXPECT_TRUE(done["state"] == "canceled" || done["state"] == "succeeded") << done.dump();
}

TEST_F(Api, ContractMatchesOpenApi) {
  auto spec = spec_routes();
  ASSERT_FALSE(spec.empty());
  std::set<std::pair<std::string, std::string>> served;
  for (const auto& r : soupuv::server::api_routes()) served.insert({r.method, r.path});
  EXPECT_EQ(spec, served) << "proto/openapi.yaml and the route table differ";
  // Every spec route is really routed: nothing answers the router's generic 404.
  auto c = server_->client();
  const std::string id = "jaaaaaaaaaaaaaaaaaaaaaaaaaa";
  for (const auto& [method, path] : spec) {
    std::string p = std::regex_replace(path, std::regex("\\{id\\}"), id);
    p = std::regex_replace(p, std::regex("\\{slug\\}"), "not-found");
    httplib::Result r = method == "get"      ? c.Get(p.c_str())
                        : method == "delete" ? c.Delete(p.c_str())
                                             : c.Post(p.c_str(), "", "model/gltf-binary");
    ASSERT_TRUE(r) << method << " " << path;
    EXPECT_EQ(r->body.find("\"detail\":\"Not Found\""), std::string::npos) << method << " " << path << " is not routed";
  }
  auto yaml = c.Get("/v1/openapi.yaml");
  ASSERT_TRUE(yaml);
  EXPECT_EQ(yaml->status, 200);
  EXPECT_NE(yaml->body.find("openapi: 3.1"), std::string::npos);
}

TEST_F(Api, OperationsEndpoints) {
  auto c = server_->client();
  EXPECT_EQ(c.Get("/healthz")->status, 200);
  auto ready = c.Get("/readyz");
  EXPECT_EQ(ready->status, 200) << ready->body;
  auto m = c.Get("/metrics");
  ASSERT_EQ(m->status, 200);
  for (const char* name : {"soupuv_http_requests_total", "soupuv_jobs{state=\"queued\"}", "soupuv_queue_depth",
                           "soupuv_cache_hits_total", "soupuv_workers_busy"})
    EXPECT_NE(m->body.find(name), std::string::npos) << name;
  auto page = c.Get("/");
  ASSERT_TRUE(page);
  EXPECT_EQ(page->status, 200);
  EXPECT_NE(page->body.find("<html"), std::string::npos);
  // three.js comes from node_modules (npm ci); without it the page loads but the viewer cannot.
  if (fs::exists(std::string(SOUPUV_SOURCE_DIR) + "/node_modules/three/build/three.module.js")) {
    EXPECT_EQ(c.Get("/assets/vendor/three.module.js")->status, 200);
  }
  expect_problem(c.Get("/assets/../../etc/passwd"), 404);
}

TEST_F(Api, FiftyMegabyteUploadStreamsToDisk) {
  // A valid GLB padded to 50 MB (an unused tail in its one buffer).
  std::string glb = read_bytes(shared_data("gltf/Box.glb"));
  auto le = [](const std::string& s, size_t o) {
    return uint32_t(uint8_t(s[o])) | uint32_t(uint8_t(s[o + 1])) << 8 | uint32_t(uint8_t(s[o + 2])) << 16 |
           uint32_t(uint8_t(s[o + 3])) << 24;
  };
  auto put = [](std::string& s, uint32_t v) { for (int i = 0; i < 4; ++i) s += char((v >> (8 * i)) & 0xff); };
  uint32_t json_len = le(glb, 12);
  json doc = json::parse(glb.substr(20, json_len));
  std::string bin = glb.substr(20 + json_len + 8, le(glb, 20 + json_len));
  bin.resize(50u << 20, '\0');
  doc["buffers"][0]["byteLength"] = bin.size();
  std::string js = doc.dump();
  while (js.size() % 4) js += ' ';
  std::string out = "glTF";
  put(out, 2);
  put(out, uint32_t(12 + 8 + js.size() + 8 + bin.size()));
  put(out, uint32_t(js.size()));
  out += "JSON" + js;
  put(out, uint32_t(bin.size()));
  out += std::string("BIN\0", 4) + bin;

  auto hwm_kb = [&] {
    std::ifstream s("/proc/" + std::to_string(server_->pid()) + "/status");
    std::string line;
    while (std::getline(s, line))
      if (line.rfind("VmHWM:", 0) == 0) return std::stol(line.substr(6));
    return 0L;
  };
  long before = hwm_kb();
  auto c = server_->client();
  auto r = submit(c, out, "model/gltf-binary", "?method=box&texture_size=64");
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 202) << r->body;
  long grown_mb = (hwm_kb() - before) / 1024;
  EXPECT_LT(grown_mb, 25) << "the server's peak memory grew by " << grown_mb << " MB for a 50 MB upload";
  auto done = wait_finished(c, json::parse(r->body)["id"], 90);
  EXPECT_EQ(done["state"], "succeeded") << done.dump();
}

TEST_F(Api, MultipartWithUserTexture) {
  auto c = server_->client();
  std::string png = read_bytes(shared_data("gltf/Fox/Texture.png"));
  httplib::MultipartFormDataItems items = {
      {"file", read_bytes(shared_data("gltf/Box.glb")), "box.glb", "model/gltf-binary"},
      {"texture", png, "t.png", "image/png"},
      {"params", R"({"method":"box"})", "", "application/json"},
  };
  auto r = c.Post("/v1/jobs", items);
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 202) << r->body;
  auto done = wait_finished(c, json::parse(r->body)["id"]);
  ASSERT_EQ(done["state"], "succeeded") << done.dump();
  auto glb = c.Get(("/v1/jobs/" + done["id"].get<std::string>() + "/result").c_str());
  ASSERT_TRUE(glb);
  // The user's PNG is embedded byte for byte.
  EXPECT_NE(glb->body.find(png.substr(0, 4096)), std::string::npos);
  httplib::MultipartFormDataItems bad = {
      {"file", read_bytes(shared_data("gltf/Box.glb")), "box.glb", "model/gltf-binary"},
      {"texture", "GIF89a", "t.gif", "image/gif"},
  };
  expect_problem(c.Post("/v1/jobs", bad), 400);
}
