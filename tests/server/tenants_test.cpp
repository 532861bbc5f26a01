// Nobody gets in by default (issue 21, item 1): a non-loopback listener needs
// --tokens-file or --allow-anonymous; tokens are >= 32 bytes and name tenants;
// a tenant sees, downloads and deletes only its own jobs (404 otherwise) and
// has its own Idempotency-Keys; a bad token is 401 invalid_token (RFC 6750);
// SIGHUP reloads the tokens file; /metrics needs a token or its own port.
#include <gtest/gtest.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <fstream>

#include "harness.h"

using namespace soupuv::test;
using nlohmann::json;
namespace fs = std::filesystem;

namespace {

const std::string kAlice = "alice-0123456789abcdefghijklmnopqrstuv";
const std::string kBob = "bob-0123456789abcdefghijklmnopqrstuvwxyz";
const std::string kSolo = "solo-0123456789abcdefghijklmnopqrstuvwx";

httplib::Headers bearer(const std::string& token) { return {{"Authorization", "Bearer " + token}}; }

fs::path tokens_file(const std::string& name, const std::string& text) {
  fs::path dir = fresh_dir(name);
  std::ofstream(dir / "tokens") << text;
  return dir / "tokens";
}

// The start must fail; returns what the server said.
std::string refused_start(const std::string& name, const std::vector<std::string>& args) {
  try {
    ServerProcess s(fresh_dir(name), args);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

int free_port() {
  int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a);
  socklen_t len = sizeof a;
  getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len);
  close(fd);
  return ntohs(a.sin_port);
}

}  // namespace

TEST(Tenants, NonLoopbackWithoutTokensIsRefused) {
  const std::vector<std::string> base = {"--worker-bin", SOUPUV_WORKER_DOUBLE};
  auto args = base;
  args.insert(args.end(), {"--host", "0.0.0.0"});
  std::string why = refused_start("anon-refused", args);
  EXPECT_NE(why.find("--tokens-file"), std::string::npos) << why;
  EXPECT_NE(why.find("--allow-anonymous"), std::string::npos) << why;
  // On purpose: allowed.
  args.insert(args.end(), {"--allow-anonymous", "true"});
  EXPECT_EQ(refused_start("anon-allowed", args), "");
  // With tokens: allowed.
  auto with_tokens = base;
  with_tokens.insert(with_tokens.end(), {"--host", "0.0.0.0", "--tokens-file",
                                         tokens_file("anon-tokens", kAlice + "\n").string()});
  EXPECT_EQ(refused_start("anon-tokens-ok", with_tokens), "");
}

TEST(Tenants, ShortTokensAreRefusedAtStart) {
  std::string why = refused_start("short-token", {"--worker-bin", SOUPUV_WORKER_DOUBLE, "--tokens-file",
                                                  tokens_file("short", "alice abc123\n").string()});
  EXPECT_NE(why.find("shorter than 32 bytes"), std::string::npos) << why;
}

TEST(Tenants, JobsAreVisibleOnlyToTheirTenant) {
  auto file = tokens_file("tenants", "alice " + kAlice + "\nbob " + kBob + "\n" + kSolo + "\n");
  auto s = with_double("tenants-server", "slow", {"--tokens-file", file.string()}, "0");
  auto c = s->client();
  const std::string id = submit_box(c, bearer(kAlice));
  ASSERT_FALSE(id.empty());
  for (int i = 0; i < 200; ++i) {
    auto r = c.Get(("/v1/jobs/" + id).c_str(), bearer(kAlice));
    if (r && json::parse(r->body)["state"] == "succeeded") break;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  EXPECT_EQ(c.Get(("/v1/jobs/" + id).c_str(), bearer(kAlice))->status, 200);
  EXPECT_EQ(c.Get(("/v1/jobs/" + id + "/result").c_str(), bearer(kAlice))->status, 200);
  for (const auto& other : {kBob, kSolo}) {
    for (const std::string path : {"", "/result", "/diagnostics"}) {
      auto r = c.Get(("/v1/jobs/" + id + path).c_str(), bearer(other));
      ASSERT_TRUE(r);
      EXPECT_EQ(r->status, 404) << path;
      EXPECT_EQ(r->get_header_value("Content-Type"), "application/problem+json");
    }
    EXPECT_EQ(c.Delete(("/v1/jobs/" + id).c_str(), bearer(other))->status, 404);
    auto list = json::parse(c.Get("/v1/jobs", bearer(other))->body);
    EXPECT_TRUE(list["jobs"].empty()) << list.dump();
  }
  auto mine = json::parse(c.Get("/v1/jobs", bearer(kAlice))->body);
  ASSERT_EQ(mine["jobs"].size(), 1u);
  EXPECT_EQ(mine["jobs"][0]["id"], id);
  // Still there for alice after the others' attempts; alice may delete it.
  EXPECT_EQ(c.Delete(("/v1/jobs/" + id).c_str(), bearer(kAlice))->status, 204);
}

TEST(Tenants, IdempotencyKeysArePerTenant) {
  auto file = tokens_file("idem", "alice " + kAlice + "\nbob " + kBob + "\n");
  auto s = with_double("idem-server", "slow", {"--tokens-file", file.string()}, "30");
  auto c = s->client();
  auto with_key = [](const std::string& token) {
    auto h = bearer(token);
    h.emplace("Idempotency-Key", "order-42");
    return h;
  };
  const std::string a1 = submit_box(c, with_key(kAlice));
  const std::string b1 = submit_box(c, with_key(kBob));
  const std::string a2 = submit_box(c, with_key(kAlice));
  ASSERT_FALSE(a1.empty());
  ASSERT_FALSE(b1.empty());
  EXPECT_NE(a1, b1) << "bob's key replayed alice's job";
  EXPECT_EQ(a1, a2) << "alice's own retry was not replayed";
}

TEST(Tenants, BadTokenIs401InvalidTokenAndBearerIsCaseInsensitive) {
  auto file = tokens_file("rfc6750", kAlice + "\n");
  auto s = with_double("rfc6750-server", "slow", {"--tokens-file", file.string()}, "1");
  auto c = s->client();
  auto none = c.Get("/v1/jobs");
  EXPECT_EQ(none->status, 401);
  EXPECT_EQ(none->get_header_value("WWW-Authenticate").find("error="), std::string::npos);
  auto bad = c.Get("/v1/jobs", bearer(kBob));
  EXPECT_EQ(bad->status, 401);
  EXPECT_NE(bad->get_header_value("WWW-Authenticate").find("error=\"invalid_token\""), std::string::npos)
      << bad->get_header_value("WWW-Authenticate");
  EXPECT_EQ(c.Get("/v1/jobs", {{"Authorization", "bearer " + kAlice}})->status, 200);
  EXPECT_EQ(c.Get("/v1/jobs", {{"Authorization", "BEARER " + kAlice}})->status, 200);
}

TEST(Tenants, SighupReloadsTheTokensFile) {
  auto file = tokens_file("sighup", "alice " + kAlice + "\n");
  auto s = with_double("sighup-server", "slow", {"--tokens-file", file.string()}, "1");
  auto c = s->client();
  EXPECT_EQ(c.Get("/v1/jobs", bearer(kAlice))->status, 200);
  EXPECT_EQ(c.Get("/v1/jobs", bearer(kBob))->status, 401);
  std::ofstream(file) << "bob " << kBob << "\n";
  ::kill(s->pid(), SIGHUP);
  int bob = 0, alice = 0;
  for (int i = 0; i < 100; ++i) {
    bob = c.Get("/v1/jobs", bearer(kBob))->status;
    alice = c.Get("/v1/jobs", bearer(kAlice))->status;
    if (bob == 200 && alice == 401) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  EXPECT_EQ(bob, 200);
  EXPECT_EQ(alice, 401);
  // A broken file keeps the tokens in force (never falls open, never locks out).
  std::ofstream(file) << "carol short\n";
  ::kill(s->pid(), SIGHUP);
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  EXPECT_EQ(c.Get("/v1/jobs", bearer(kBob))->status, 200);
  EXPECT_EQ(c.Get("/v1/jobs")->status, 401);
  EXPECT_NE(s->log().find("tokens file not reloaded"), std::string::npos);
}

TEST(Tenants, MetricsNeedATokenOrTheirOwnPort) {
  auto file = tokens_file("metrics", kAlice + "\n");
  const int mport = free_port();
  auto s = with_double("metrics-server", "slow",
                       {"--tokens-file", file.string(), "--metrics-port", std::to_string(mport)}, "1");
  auto c = s->client();
  EXPECT_EQ(c.Get("/metrics")->status, 401);
  auto ok = c.Get("/metrics", bearer(kAlice));
  EXPECT_EQ(ok->status, 200);
  EXPECT_NE(ok->body.find("soupuv_queue_depth"), std::string::npos);
  httplib::Client m("127.0.0.1", mport);
  auto scraped = m.Get("/metrics");
  ASSERT_TRUE(scraped);
  EXPECT_EQ(scraped->status, 200);
  EXPECT_NE(scraped->body.find("soupuv_queue_depth"), std::string::npos);
  auto api = m.Get("/v1/jobs");  // the metrics port serves nothing else
  ASSERT_TRUE(api);
  EXPECT_EQ(api->status, 404);
}
