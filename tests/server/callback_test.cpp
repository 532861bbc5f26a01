// Job metadata and job-end callbacks: metadata stored and returned (and
// refused above 4 KiB); a callback POSTed to a real receiving HTTP server on
// loopback (allowed explicitly by flag), signed with HMAC-SHA256, retried after
// a 503; loopback refused without the flag (the SSRF guard); the address
// classifier and the HMAC against RFC 4231.
#include <gtest/gtest.h>

#include <chrono>
#include <mutex>
#include <thread>

#include "harness.h"
#include "soupuv/server/callbacks.h"

using namespace soupuv::test;
using nlohmann::json;
using soupuv::server::check_callback_url;
using soupuv::server::hmac_sha256_hex;
using soupuv::server::is_public_address;

namespace {

TEST(Callbacks, PublicAddressesOnly) {
  for (const char* a : {"127.0.0.1", "10.1.2.3", "172.16.0.1", "172.31.255.255", "192.168.1.1", "169.254.169.254",
                        "100.64.0.1", "0.0.0.0", "224.0.0.1", "::1", "::", "fe80::1", "fc00::1", "fd12::1",
                        "::ffff:127.0.0.1", "::ffff:10.0.0.1", "not an address"})
    EXPECT_FALSE(is_public_address(a)) << a;
  for (const char* a : {"8.8.8.8", "1.1.1.1", "172.32.0.1", "2001:4860:4860::8888", "::ffff:8.8.8.8"})
    EXPECT_TRUE(is_public_address(a)) << a;
}

TEST(Callbacks, HmacMatchesRfc4231) {
  EXPECT_EQ(hmac_sha256_hex("Jefe", "what do ya want for nothing?"),
            "5bdcc146bf60754e6a042426089575c75a003f089d2739839dec58b964ec3843");
}

TEST(Callbacks, UrlShapes) {
  EXPECT_EQ(check_callback_url("https://hooks.example.com/soupuv?x=1"), "");
  EXPECT_EQ(check_callback_url("http://127.0.0.1:8080/hook"), "");
  for (const char* bad : {"ftp://example.com/", "http://user:pw@example.com/", "example.com/hook", "http://", ""})
    EXPECT_NE(check_callback_url(bad), "") << bad;
}

// A receiving server: answers the first `fail_first` POSTs 503, then 204.
struct Receiver {
  httplib::Server http;
  std::thread thread;
  int port = 0, fail_first = 1;
  std::mutex mu;
  std::vector<std::pair<std::string, std::string>> received;  // (signature header, body)
  explicit Receiver(int fail) : fail_first(fail) {
    http.Post("/hook", [this](const httplib::Request& req, httplib::Response& res) {
      std::lock_guard lock(mu);
      received.push_back({req.get_header_value("Soupuv-Signature"), req.body});
      res.status = int(received.size()) <= fail_first ? 503 : 204;
    });
    port = http.bind_to_any_port("127.0.0.1");
    thread = std::thread([this] { http.listen_after_bind(); });
  }
  ~Receiver() {
    http.stop();
    thread.join();
  }
  size_t count() {
    std::lock_guard lock(mu);
    return received.size();
  }
};

bool wait_for(const std::function<bool()>& done, double seconds) {
  for (auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
       std::chrono::steady_clock::now() < end; std::this_thread::sleep_for(std::chrono::milliseconds(100)))
    if (done()) return true;
  return done();
}

class CallbackJobs : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!cli_available()) GTEST_SKIP() << "the soupuv CLI was not built; end-to-end tests need it";
    box_ = read_bytes(shared_data("gltf/Box.glb"));
  }
  std::unique_ptr<ServerProcess> start(std::vector<std::string> extra) {
    std::vector<std::string> args = {"--worker-bin", SOUPUV_CLI_BIN, "--workers", "1"};
    args.insert(args.end(), extra.begin(), extra.end());
    return std::make_unique<ServerProcess>(fresh_dir("callbacks"), args);
  }
  std::string box_;
};

TEST_F(CallbackJobs, SignedRetriedAndCarriesMetadata) {
  Receiver receiver(1);
  auto server = start({"--callback-secret", "s3cret", "--callback-allow-private", "true"});
  auto c = server->client();
  const json params = {{"method", "box"},
                       {"callback_url", "http://127.0.0.1:" + std::to_string(receiver.port) + "/hook"},
                       {"metadata", {{"asset_id", "A-42"}, {"tags", {"chair", "oak"}}}}};
  httplib::MultipartFormDataItems items = {{"file", box_, "Box.glb", "model/gltf-binary"},
                                           {"params", params.dump(), "", "application/json"}};
  auto r = c.Post("/v1/jobs", items);
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 202) << r->body;
  const json job = json::parse(r->body);
  EXPECT_EQ(job["metadata"]["asset_id"], "A-42");
  auto got = c.Get(("/v1/jobs/" + job["id"].get<std::string>()).c_str());
  ASSERT_TRUE(got);
  EXPECT_EQ(json::parse(got->body)["metadata"], params["metadata"]);
  // First POST answered 503, the retry about a second later 204.
  ASSERT_TRUE(wait_for([&] { return receiver.count() >= 2; }, 60)) << server->log();
  std::lock_guard lock(receiver.mu);
  const auto& [signature, body] = receiver.received.back();
  const json sent = json::parse(body);
  EXPECT_EQ(sent["id"], job["id"]);
  EXPECT_EQ(sent["state"], "succeeded");
  EXPECT_EQ(sent["metadata"]["asset_id"], "A-42");
  // Soupuv-Signature: t=<seconds>,v1=HMAC-SHA256(secret, "<t>.<body>")
  const size_t comma = signature.find(",v1=");
  ASSERT_EQ(signature.rfind("t=", 0), 0u) << signature;
  ASSERT_NE(comma, std::string::npos) << signature;
  const std::string t = signature.substr(2, comma - 2);
  EXPECT_EQ(signature.substr(comma + 4), hmac_sha256_hex("s3cret", t + "." + body));
  EXPECT_NE(signature.substr(comma + 4), hmac_sha256_hex("other", t + "." + body));
}

TEST_F(CallbackJobs, LoopbackRefusedWithoutTheFlag) {
  Receiver receiver(0);
  auto server = start({"--callback-secret", "s3cret"});
  auto c = server->client();
  const json params = {{"method", "box"},
                       {"callback_url", "http://localhost:" + std::to_string(receiver.port) + "/hook"}};
  auto r = submit(c, box_, "model/gltf-binary", "?params=" + httplib::detail::encode_query_param(params.dump()));
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 202) << r->body;
  ASSERT_TRUE(wait_for([&] { return server->log().find("callback failed") != std::string::npos; }, 60));
  EXPECT_NE(server->log().find("loopback, private or reserved"), std::string::npos) << server->log();
  EXPECT_EQ(receiver.count(), 0u);
}

TEST_F(CallbackJobs, Refusals) {
  auto plain = start({});
  auto c = plain->client();
  auto problem = [&](const json& params, int status, const std::string& part) {
    httplib::MultipartFormDataItems items = {{"file", box_, "Box.glb", "model/gltf-binary"},
                                             {"params", params.dump(), "", "application/json"}};
    auto r = c.Post("/v1/jobs", items);
    ASSERT_TRUE(r);
    EXPECT_EQ(r->status, status) << r->body;
    EXPECT_EQ(r->get_header_value("Content-Type"), "application/problem+json");
    EXPECT_NE(r->body.find(part), std::string::npos) << r->body;
  };
  problem({{"metadata", {{"blob", std::string(5000, 'x')}}}}, 413, "4096");
  problem({{"metadata", "not an object"}}, 400, "metadata must be a JSON object");
  problem({{"callback_url", "http://example.com/hook"}}, 400, "--callback-secret");
  problem({{"callback_url", "gopher://example.com/"}}, 400, "http:// or https://");
}

}  // namespace
