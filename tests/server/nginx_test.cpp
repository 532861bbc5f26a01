// deploy/nginx/soupuv.conf in front of a real soupuv-server, all on loopback:
// a job goes through the proxy, and the proxy keeps the server's refusals.
#include <gtest/gtest.h>

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fstream>
#include <regex>

#include "harness.h"

using namespace soupuv::test;
using nlohmann::json;
namespace fs = std::filesystem;

namespace {

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

struct Nginx {
  pid_t pid = -1;
  int port = 0;
  ~Nginx() {
    if (pid > 0) {
      kill(pid, SIGTERM);
      int st;
      waitpid(pid, &st, 0);
    }
  }
};

}  // namespace

TEST(Nginx, ReverseProxyOnLoopback) {
  const char* nginx_bin = "/usr/sbin/nginx";
  if (access(nginx_bin, X_OK) != 0) GTEST_SKIP() << "nginx is not installed";
  if (!cli_available()) GTEST_SKIP() << "needs the real soupuv CLI";
  ServerProcess server(fresh_dir("nginx-backend"), {"--worker-bin", SOUPUV_CLI_BIN});
  fs::path dir = fresh_dir("nginx");
  std::string site = read_bytes(std::string(SOUPUV_SOURCE_DIR) + "/deploy/nginx/soupuv.conf");
  Nginx nginx;
  nginx.port = free_port();
  site = std::regex_replace(site, std::regex("server soupuv:8080;"), "server 127.0.0.1:" + std::to_string(server.port()) + ";");
  site = std::regex_replace(site, std::regex("listen 80;"), "listen 127.0.0.1:" + std::to_string(nginx.port) + ";");
  const std::string d = dir.string();
  std::ofstream(dir / "nginx.conf") << "pid " << d << "/nginx.pid; error_log " << d << "/error.log; events {}\n"
                                    << "http { access_log off; client_body_temp_path " << d << "/body; proxy_temp_path " << d
                                    << "/proxy; fastcgi_temp_path " << d << "/f; uwsgi_temp_path " << d
                                    << "/u; scgi_temp_path " << d << "/s;\n" << site << "\n}\n";
  nginx.pid = fork();
  if (nginx.pid == 0) {
    int devnull = open("/dev/null", O_RDWR);
    dup2(devnull, 1);
    execl(nginx_bin, nginx_bin, "-p", d.c_str(), "-c", (d + "/nginx.conf").c_str(), "-g", "daemon off;", nullptr);
    _exit(127);
  }
  httplib::Client c("127.0.0.1", nginx.port);
  c.set_read_timeout(30, 0);
  bool up = false;
  for (int i = 0; i < 100 && !up; ++i) {
    auto r = c.Get("/healthz");
    up = r && r->status == 200;
    if (!up) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  ASSERT_TRUE(up) << read_bytes(dir / "error.log");

  auto r = submit(c, read_bytes(shared_data("gltf/Box.glb")), "model/gltf-binary", "?method=box");
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 202) << r->body;
  auto done = wait_finished(c, json::parse(r->body)["id"]);
  EXPECT_EQ(done["state"], "succeeded");
  auto glb = c.Get(("/v1/jobs/" + done["id"].get<std::string>() + "/result").c_str());
  ASSERT_TRUE(glb);
  EXPECT_EQ(glb->body.substr(0, 4), "glTF");
  // Refusals still happen before the body: nginx's own cap, the server's guards.
  std::string big = raw_exchange(nginx.port, "POST /v1/jobs HTTP/1.1\r\nHost: x\r\nContent-Type: model/gltf-binary\r\n"
                                             "Content-Length: 1073741824\r\n\r\n");
  EXPECT_EQ(status_of(big), 413) << big;
  auto bad = submit(c, read_bytes(shared_data("bad/truncated.glb")), "model/gltf-binary");
  ASSERT_TRUE(bad);
  EXPECT_EQ(bad->status, 400);
  EXPECT_EQ(bad->get_header_value("Content-Type"), "application/problem+json");
  std::string chunked = raw_exchange(nginx.port, "POST /v1/jobs HTTP/1.1\r\nHost: x\r\nContent-Type: model/gltf-binary\r\n"
                                                 "Transfer-Encoding: chunked\r\n\r\n4\r\nglTF\r\n0\r\n\r\n");
  EXPECT_GE(status_of(chunked), 400) << chunked;
  EXPECT_LT(status_of(chunked), 500) << chunked;
  auto metrics = c.Get("/metrics");  // only from loopback, which we are
  EXPECT_EQ(metrics->status, 200);
}
