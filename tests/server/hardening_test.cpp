// HTTP hardening with raw sockets (httplib's client would normalise what we
// need to send wrong): every refusal comes before the body, as problem+json,
// and the server goes on serving.
#include <gtest/gtest.h>

#include <chrono>

#include "harness.h"

using namespace soupuv::test;

namespace {

class Hardening : public ::testing::Test {
 protected:
  void SetUp() override {
    // The CLI is not needed to refuse requests; without it the server still
    // runs (submissions that pass every guard would get 503).
    std::vector<std::string> args = {"--max-upload-bytes", "104857600"};
    if (cli_available()) args.insert(args.end(), {"--worker-bin", SOUPUV_CLI_BIN});
    server_ = std::make_unique<ServerProcess>(fresh_dir("hardening"), args);
  }
  std::string post(const std::string& extra_headers, const std::string& body = "") {
    return raw_exchange(server_->port(), "POST /v1/jobs HTTP/1.1\r\nHost: 127.0.0.1\r\n" + extra_headers + "\r\n" + body);
  }
  void expect_refused(const std::string& response, int status) {
    EXPECT_EQ(status_of(response), status) << response;
    EXPECT_NE(response.find("Content-Type: application/problem+json"), std::string::npos) << response;
    EXPECT_NE(response.find("\"status\":" + std::to_string(status)), std::string::npos) << response;
  }
  void TearDown() override {
    if (!server_) return;
    auto c = server_->client();
    auto h = c.Get("/healthz");
    ASSERT_TRUE(h) << "server stopped serving";
    EXPECT_EQ(h->status, 200);
  }
  std::unique_ptr<ServerProcess> server_;
};

}  // namespace

TEST_F(Hardening, TransferEncodingIsLengthRequired) {
  expect_refused(post("Content-Type: model/gltf-binary\r\nTransfer-Encoding: chunked\r\n", "5\r\nhello\r\n0\r\n\r\n"), 411);
}

TEST_F(Hardening, ContentEncodingIsRefused) {
  expect_refused(post("Content-Type: model/gltf-binary\r\nContent-Encoding: gzip\r\nContent-Length: 4\r\n", "abcd"), 415);
}

TEST_F(Hardening, MissingAndDuplicateContentLength) {
  expect_refused(post("Content-Type: model/gltf-binary\r\n"), 411);
  expect_refused(post("Content-Type: model/gltf-binary\r\nContent-Length: 4\r\nContent-Length: 4\r\n", "abcd"), 411);
  expect_refused(post("Content-Type: model/gltf-binary\r\nContent-Length: 4x\r\n", "abcd"), 411);
}

TEST_F(Hardening, OneGigabyteRefusedBeforeItIsRead) {
  // Only the headers are sent: an answer proves the server did not wait for
  // (or read) the gigabyte.
  auto t0 = std::chrono::steady_clock::now();
  std::string r = post("Content-Type: model/gltf-binary\r\nContent-Length: 1073741824\r\n");
  double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  expect_refused(r, 413);
  EXPECT_NE(r.find("Connection: close"), std::string::npos) << "unread body: the connection must close";
  EXPECT_LT(secs, 3.5);
}

TEST_F(Hardening, ExpectContinueGetsTheFinalAnswerFirst) {
  std::string r = post("Content-Type: model/gltf-binary\r\nContent-Length: 1073741824\r\nExpect: 100-continue\r\n");
  EXPECT_EQ(r.find("100 Continue"), std::string::npos) << r;
  expect_refused(r, 413);
  // Without a length the client would wait for a close while sending its body.
  EXPECT_NE(r.find("Content-Length: "), std::string::npos) << r;
  std::string bad_type = post("Content-Type: text/csv\r\nContent-Length: 10\r\nExpect: 100-continue\r\n");
  expect_refused(bad_type, 415);
  // An acceptable request is told to go on.
  std::string ok = raw_exchange(server_->port(),
                                "POST /v1/jobs HTTP/1.1\r\nHost: x\r\nContent-Type: model/gltf-binary\r\n"
                                "Content-Length: 10\r\nExpect: 100-continue\r\n\r\n",
                                800);
  EXPECT_EQ(ok.rfind("HTTP/1.1 100 Continue", 0), 0u) << ok;
}

TEST_F(Hardening, LongPathAndUnknownTypeAndBodyOnGet) {
  std::string r = raw_exchange(server_->port(), "GET /" + std::string(3000, 'a') + " HTTP/1.1\r\nHost: x\r\n\r\n");
  expect_refused(r, 414);
  expect_refused(post("Content-Type: application/x-www-form-urlencoded\r\nContent-Length: 3\r\n", "a=b"), 415);
  expect_refused(raw_exchange(server_->port(), "GET /healthz HTTP/1.1\r\nHost: x\r\nContent-Length: 5\r\n\r\nhello"), 405);
}

TEST_F(Hardening, HeaderValuesAreNotEchoed) {
  const std::string marker = "%3Cscript%3Eecho-me%3C%2Fscript%3E";
  std::string r = raw_exchange(server_->port(),
                               "POST /v1/jobs HTTP/1.1\r\nHost: x\r\nContent-Type: text/" + marker +
                                   "\r\nX-Trace: " + marker + "\r\nContent-Length: 1\r\n\r\na");
  EXPECT_EQ(status_of(r), 415);
  EXPECT_EQ(r.find("echo-me"), std::string::npos) << r;
  EXPECT_EQ(server_->log().find("echo-me"), std::string::npos) << "a header value reached the log";
}

TEST_F(Hardening, GarbageRequestLine) {
  std::string r = raw_exchange(server_->port(), "NONSENSE\r\n\r\n", 1500);
  EXPECT_TRUE(r.empty() || (status_of(r) >= 400 && status_of(r) < 500)) << r;
}

TEST_F(Hardening, RefusedBodyIsNeverParsedAsASecondRequest) {
  const std::string smuggled = "GET /v1/jobs HTTP/1.1\r\nHost: x\r\n\r\n";
  std::string r = post("Content-Type: text/plain\r\nContent-Length: " + std::to_string(smuggled.size()) + "\r\n", smuggled);
  EXPECT_EQ(status_of(r), 415) << r;
  size_t responses = 0;
  for (size_t p = r.find("HTTP/1.1 "); p != std::string::npos; p = r.find("HTTP/1.1 ", p + 1)) ++responses;
  EXPECT_EQ(responses, 1u) << r;
  std::string te = post("Content-Type: model/gltf-binary\r\nTransfer-Encoding: chunked\r\n", smuggled);
  EXPECT_EQ(status_of(te), 411) << te;
  EXPECT_EQ(te.find("\"jobs\""), std::string::npos) << te;
}

namespace {
size_t count_responses(const std::string& r) {
  size_t n = 0;
  for (size_t p = r.find("HTTP/1.1 "); p != std::string::npos; p = r.find("HTTP/1.1 ", p + 1)) ++n;
  return n;
}
}  // namespace

TEST_F(Hardening, KeepAliveCarriesSeveralGoodRequests) {
  // Three pipelined requests on one connection; the last asks to close.
  const std::string get = "GET /healthz HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n";
  auto t0 = std::chrono::steady_clock::now();
  std::string r = raw_exchange(server_->port(),
                               get + "GET /v1/jobs HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n" +
                                   "GET /healthz HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n",
                               5000);
  double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_EQ(count_responses(r), 3u) << r;
  EXPECT_NE(r.find("\"jobs\""), std::string::npos) << r;
  EXPECT_LT(secs, 4.0) << "the server did not close after Connection: close";
}

TEST_F(Hardening, EveryRefusalWithAnUnreadBodyClosesTheConnection) {
  // Each request announces a body that is itself a request. Whatever refuses
  // it (guard, route table, submit handler), the answer is one response and
  // the connection is closed: the body is never parsed as a second request.
  const std::string smuggled = "GET /v1/jobs HTTP/1.1\r\nHost: x\r\n\r\n";
  const std::string len = "Content-Length: " + std::to_string(smuggled.size()) + "\r\n";
  struct Case {
    const char* what;
    std::string head;
    int status;
  };
  const std::vector<Case> cases = {
      {"unknown type (guard)", "POST /v1/jobs HTTP/1.1\r\nHost: x\r\nContent-Type: text/plain\r\n" + len, 415},
      {"body on a GET route (guard)", "POST /healthz HTTP/1.1\r\nHost: x\r\nContent-Type: model/gltf-binary\r\n" + len, 405},
      {"bad parameter (submit handler, before the body)",
       "POST /v1/jobs?method=magic HTTP/1.1\r\nHost: x\r\nContent-Type: model/gltf-binary\r\n" + len, 400},
      {"bad idempotency key (submit handler)",
       "POST /v1/jobs HTTP/1.1\r\nHost: x\r\nContent-Type: model/gltf-binary\r\nIdempotency-Key: a b\r\n" + len, 400},
  };
  for (const auto& c : cases) {
    auto t0 = std::chrono::steady_clock::now();
    std::string r = raw_exchange(server_->port(), c.head + "\r\n" + smuggled, 4000);
    double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    EXPECT_EQ(status_of(r), c.status) << c.what << ": " << r;
    EXPECT_EQ(count_responses(r), 1u) << c.what << ": " << r;
    EXPECT_EQ(r.find("\"jobs\""), std::string::npos) << c.what << ": the body was parsed as a request";
    EXPECT_LT(secs, 3.0) << c.what << ": the connection was kept open";
  }
}
