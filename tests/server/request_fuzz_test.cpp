// A property test of the request path (issue 21, targets): for
// SOUPUV_REQUEST_FUZZ_SECONDS (default 10; scripts/test.sh runs 60) eight
// clients send random requests — random methods, paths, header names and
// values (control bytes, huge values, duplicate or lying Content-Length,
// Transfer-Encoding, Expect), random bodies in random pieces with random
// pauses, early hang-ups — while a monitor polls /healthz. Properties: every
// answer is an HTTP/1.1 status line with a 1xx-5xx code, /healthz answers
// within 2 s throughout, and the server is alive at the end.
// SOUPUV_REQUEST_FUZZ_SEED replays a run (the seed is printed).
#include <gtest/gtest.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <random>

#include "harness.h"

using namespace soupuv::test;
using Clock = std::chrono::steady_clock;

namespace {

class RandomRequest {
 public:
  explicit RandomRequest(uint64_t seed) : rng_(seed) {}

  std::string next(bool& slow) {
    static const char* methods[] = {"GET", "POST", "DELETE", "PUT", "OPTIONS", "HEAD", "PATCH", "G\x01T", "POST "};
    static const char* paths[] = {"/healthz", "/readyz", "/metrics", "/v1/jobs", "/v1/jobs?limit=1000&cursor=%00",
                                  "/v1/jobs/jaaaaaaaaaaaaaaaaaaaaaaaaaa", "/v1/jobs/jaaaaaaaaaaaaaaaaaaaaaaaaaa:cancel",
                                  "/v1/jobs/jaaaaaaaaaaaaaaaaaaaaaaaaaa/result", "/v1/params", "/problems/not-found",
                                  "/", "/assets/../../etc/passwd", "/v1/jobs?params={\"method\":1}", "*"};
    std::string method = pick(methods), path = pick(paths);
    if (chance(0.1)) path = "/" + bytes(size_t(uniform(1, 3000)));
    std::string req = method + " " + path + (chance(0.95) ? " HTTP/1.1" : " HTTP/9.9") + "\r\n";
    if (chance(0.9)) req += "Host: fuzz\r\n";
    const int headers = uniform(0, chance(0.05) ? 300 : 12);
    size_t body_len = size_t(chance(0.5) ? uniform(0, 4096) : uniform(0, 200000));
    for (int i = 0; i < headers; ++i) {
      switch (uniform(0, 9)) {
        case 0: req += "Content-Length: " + std::to_string(chance(0.5) ? body_len : size_t(uniform(0, 1 << 30))) + "\r\n"; break;
        case 1: req += "Content-Length: " + std::string(chance(0.5) ? "-1" : "12abc") + "\r\n"; break;
        case 2: req += "Transfer-Encoding: chunked\r\n"; break;
        case 3: req += "Expect: 100-continue\r\n"; break;
        case 4: req += "Content-Type: " + std::string(chance(0.5) ? "model/gltf-binary" : "multipart/form-data; boundary=x") + "\r\n"; break;
        case 5: req += "Authorization: Bearer " + bytes(size_t(uniform(0, 64))) + "\r\n"; break;
        case 6: req += "X-" + bytes(size_t(uniform(1, 20))) + ": " + bytes(size_t(uniform(0, chance(0.1) ? 30000 : 100))) + "\r\n"; break;
        case 7: req += "Idempotency-Key: " + bytes(size_t(uniform(0, 200))) + "\r\n"; break;
        case 8: req += "Connection: " + std::string(chance(0.5) ? "close" : "keep-alive") + "\r\n"; break;
        default: req += bytes(size_t(uniform(0, 40))) + "\r\n"; break;  // not a header at all
      }
    }
    if (chance(0.95)) req += "\r\n";
    if (method == "POST" || chance(0.2)) {
      std::string body = chance(0.5) ? bytes(body_len) : std::string(body_len, 'g');
      if (chance(0.3) && body.size() >= 4) body.replace(0, 4, "glTF");
      req += body;
    }
    slow = chance(0.1) && req.size() < 8192;  // trickled byte by byte, a big body would outlast the run
    return req;
  }

  int uniform(int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng_); }
  bool chance(double p) { return std::bernoulli_distribution(p)(rng_); }

 private:
  template <size_t N>
  std::string pick(const char* const (&a)[N]) { return a[size_t(uniform(0, int(N) - 1))]; }
  std::string bytes(size_t n) {
    std::string s(n, '\0');
    for (auto& c : s) c = char(uniform(chance(0.9) ? 32 : 0, chance(0.9) ? 126 : 255));
    return s;
  }
  std::mt19937_64 rng_;
};

int connect_to(int port) { return loopback_connect(port); }

// Sends `req` (in random pieces with pauses when `slow`), reads the answer;
// empty when the server closed without one (allowed: e.g. a hang-up).
std::string exchange(int port, const std::string& req, bool slow, RandomRequest& r, Clock::time_point until_run) {
  int fd = connect_to(port);
  if (fd < 0) return "connect failed";
  size_t sent = 0;
  const bool hang_up = r.chance(0.05);
  const size_t stop_at = hang_up ? size_t(r.uniform(0, int(req.size()))) : req.size();
  while (sent < stop_at && Clock::now() < until_run + std::chrono::seconds(2)) {
    size_t piece = slow ? size_t(r.uniform(1, 64)) : stop_at - sent;
    ssize_t n = send(fd, req.data() + sent, std::min(piece, stop_at - sent), MSG_NOSIGNAL);
    if (n <= 0) break;
    sent += size_t(n);
    if (slow) std::this_thread::sleep_for(std::chrono::milliseconds(r.uniform(0, 30)));
  }
  std::string answer;
  if (!hang_up) {
    auto until = Clock::now() + std::chrono::seconds(3);
    while (Clock::now() < until && answer.find("\r\n") == std::string::npos) {
      pollfd p{fd, POLLIN, 0};
      if (poll(&p, 1, 50) <= 0) continue;
      char buf[4096];
      ssize_t n = recv(fd, buf, sizeof buf, 0);
      if (n <= 0) break;
      answer.append(buf, size_t(n));
    }
  }
  close(fd);
  return answer;
}

}  // namespace

TEST(RequestFuzz, RandomRequestsNeverCrashHangOrStarveHealthz) {
  const char* secs_env = std::getenv("SOUPUV_REQUEST_FUZZ_SECONDS");
  const double seconds = secs_env ? std::atof(secs_env) : 10.0;
  const char* seed_env = std::getenv("SOUPUV_REQUEST_FUZZ_SEED");
  const uint64_t seed = seed_env ? std::strtoull(seed_env, nullptr, 10) : std::random_device{}();
  std::printf("request fuzz: %.0f s, SOUPUV_REQUEST_FUZZ_SEED=%llu\n", seconds, (unsigned long long)seed);
  auto s = with_double("request-fuzz", "slow",
                       {"--queue-capacity", "5", "--max-upload-bytes", "100000", "--header-timeout", "2"}, "1");
  const int port = s->port();
  const Clock::time_point until =
      Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));

  std::atomic<int> bad_answers{0}, requests{0}, health_failures{0};
  std::atomic<double> worst_health{0};
  std::string first_bad;
  std::mutex bad_mu;
  std::vector<std::thread> clients;
  for (int t = 0; t < 8; ++t)
    clients.emplace_back([&, t] {
      RandomRequest r(seed + uint64_t(t));
      while (Clock::now() < until) {
        bool slow = false;
        const std::string req = r.next(slow);
        const std::string answer = exchange(port, req, slow, r, until);
        ++requests;
        if (answer.empty()) continue;
        const bool ok = answer.rfind("HTTP/1.1 ", 0) == 0 && answer.size() >= 12 &&
                        std::isdigit(static_cast<unsigned char>(answer[9])) && answer[9] >= '1' && answer[9] <= '5';
        if (!ok) {
          ++bad_answers;
          std::lock_guard lock(bad_mu);
          if (first_bad.empty()) first_bad = answer.substr(0, 120);
        }
      }
    });
  std::thread monitor([&] {
    while (Clock::now() < until) {
      httplib::Client c("127.0.0.1", port);
      c.set_connection_timeout(2, 0);
      c.set_read_timeout(2, 0);
      auto t0 = Clock::now();
      auto res = c.Get("/healthz");
      double took = std::chrono::duration<double>(Clock::now() - t0).count();
      if (!res || res->status != 200) ++health_failures;
      if (took > worst_health) worst_health = took;
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
    }
  });
  for (auto& c : clients) c.join();
  monitor.join();

  EXPECT_EQ(::kill(s->pid(), 0), 0) << "the server died";
  EXPECT_EQ(bad_answers.load(), 0) << "first: " << first_bad;
  EXPECT_EQ(health_failures.load(), 0) << "/healthz failed or took > 2 s";
  EXPECT_LT(worst_health.load(), 2.0);
  EXPECT_GT(requests.load(), 8);
  auto c = s->client();
  auto h = c.Get("/healthz");
  ASSERT_TRUE(h);
  EXPECT_EQ(h->status, 200);
  EXPECT_EQ(s->log().find("terminate"), std::string::npos);
  std::printf("request fuzz: %d requests, worst /healthz %.3f s\n", requests.load(), worst_health.load());
}
