// The HTTP layer holds under abuse (issue 21, item 5): slow clients hold no
// HTTP thread (64 of them and /healthz still answers at once), a head that
// does not arrive in time is 408, one too large 431, both before httplib
// buffers it; `Expect: 100-continue` gets the body path's queue and disk
// refusals; a refusal is read by the client, not reset.
#include <gtest/gtest.h>

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstring>

#include "harness.h"

using namespace soupuv::test;
using nlohmann::json;
using Clock = std::chrono::steady_clock;

namespace {

int connect_to(int port) { return loopback_connect(port); }

std::string read_all(int fd, int ms) { return read_until_close(fd, ms); }

double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

}  // namespace

TEST(HttpAbuse, SixtyFourSlowClientsDoNotStopHealthz) {
  auto s = with_double("slowloris", "slow", {}, "1");
  std::vector<int> slow;
  for (int i = 0; i < 64; ++i) {
    int fd = connect_to(s->port());
    ASSERT_GE(fd, 0);
    // A head that never ends (slowloris): each holds a thread in a
    // thread-per-connection server until its read timeout (30 s).
    const std::string part = "GET /healthz HTTP/1.1\r\nHost: x\r\nX-Slow: ";
    ASSERT_EQ(send(fd, part.data(), part.size(), MSG_NOSIGNAL), ssize_t(part.size()));
    slow.push_back(fd);
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  std::vector<double> took;
  for (int i = 0; i < 5; ++i) {
    httplib::Client c("127.0.0.1", s->port());
    c.set_connection_timeout(5, 0);
    c.set_read_timeout(5, 0);
    auto t0 = Clock::now();
    auto r = c.Get("/healthz");
    took.push_back(seconds_since(t0));
    ASSERT_TRUE(r) << "no answer within 5 s";
    EXPECT_EQ(r->status, 200);
  }
  std::sort(took.begin(), took.end());
  EXPECT_LT(took[2], 0.1) << "median /healthz time with 64 slow clients";
  EXPECT_LT(took.back(), 1.0);
  for (int fd : slow) close(fd);
}

TEST(HttpAbuse, HeadNotCompleteInTimeIs408AndClosed) {
  auto s = with_double("slowhead", "slow", {"--header-timeout", "1"}, "1");
  int fd = connect_to(s->port());
  ASSERT_GE(fd, 0);
  const std::string part = "GET /healthz HTTP/1.1\r\nHost: x\r\n";
  send(fd, part.data(), part.size(), MSG_NOSIGNAL);
  auto t0 = Clock::now();
  std::string answer = read_all(fd, 5000);
  close(fd);
  EXPECT_EQ(status_of(answer), 408) << answer;
  EXPECT_NE(answer.find("application/problem+json"), std::string::npos);
  EXPECT_LT(seconds_since(t0), 3.0);
}

TEST(HttpAbuse, OversizedHeadsAre431BeforeHttplibBuffersThem) {
  auto s = with_double("bighead", "slow", {}, "1");
  // One huge header (64 KiB), then many small ones.
  std::string big = "GET /healthz HTTP/1.1\r\nHost: x\r\nX-Big: " + std::string(65536, 'a') + "\r\n\r\n";
  EXPECT_EQ(status_of(raw_exchange(s->port(), big)), 431);
  std::string many = "GET /healthz HTTP/1.1\r\nHost: x\r\n";
  for (int i = 0; i < 200; ++i) many += "X-H" + std::to_string(i) + ": 1\r\n";
  many += "\r\n";
  EXPECT_EQ(status_of(raw_exchange(s->port(), many)), 431);
  // Within the bounds, served.
  EXPECT_EQ(status_of(raw_exchange(s->port(), "GET /healthz HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n")), 200);
}

TEST(HttpAbuse, ExpectContinueGetsTheQueueAndDiskRefusals) {
  auto s = with_double("expect", "slow", {"--workers", "1", "--queue-capacity", "1"});
  auto c = s->client();
  const std::string running = submit_box(c);
  ASSERT_EQ(wait_state(c, running, "running")["state"], "running");
  ASSERT_FALSE(submit_box(c).empty());  // the queue is now full
  const std::string head =
      "POST /v1/jobs HTTP/1.1\r\nHost: x\r\nContent-Type: model/gltf-binary\r\nContent-Length: 1000000\r\n"
      "Expect: 100-continue\r\n\r\n";
  std::string answer = raw_exchange(s->port(), head, 2000);
  EXPECT_EQ(status_of(answer), 429) << answer.substr(0, 200);  // not "100 Continue"
  EXPECT_NE(answer.find("Retry-After"), std::string::npos);

  auto low = with_double("expect-disk", "slow", {"--min-free-mb", "1000000000"}, "1");
  answer = raw_exchange(low->port(), head, 2000);
  EXPECT_EQ(status_of(answer), 503) << answer.substr(0, 200);
  EXPECT_NE(answer.find("insufficient-storage"), std::string::npos);
}

TEST(HttpAbuse, RefusalIsReadByTheClientNotReset) {
  auto s = with_double("linger", "slow", {"--max-upload-bytes", "1000"}, "1");
  // A client like curl without Expect: it sends the whole request, and only
  // then reads. The server refuses at the head (413); closing at once would
  // reset the connection under the client's writes, and it would never see
  // the 413. Lingering, the server drains the body, then the client reads.
  int fd = connect_to(s->port());
  ASSERT_GE(fd, 0);
  const std::string body(4 << 20, 'x');
  const std::string out = "POST /v1/jobs HTTP/1.1\r\nHost: x\r\nContent-Type: model/gltf-binary\r\nContent-Length: " +
                          std::to_string(body.size()) + "\r\n\r\n" + body;
  size_t sent = 0;
  int send_error = 0;
  auto until = Clock::now() + std::chrono::seconds(10);
  while (sent < out.size() && Clock::now() < until) {
    pollfd p{fd, POLLOUT, 0};
    if (poll(&p, 1, 50) <= 0) continue;
    ssize_t n = send(fd, out.data() + sent, out.size() - sent, MSG_NOSIGNAL | MSG_DONTWAIT);
    if (n > 0) sent += size_t(n);
    else if (n < 0 && errno != EAGAIN && errno != EINTR) {
      send_error = errno;
      break;
    }
  }
  std::string answer = read_all(fd, 3000);
  close(fd);
  EXPECT_EQ(send_error, 0) << std::strerror(send_error);
  EXPECT_EQ(sent, out.size());
  EXPECT_EQ(status_of(answer), 413) << answer.substr(0, 200);
}
