#include "harness.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <fstream>
#include <regex>
#include <stdexcept>
#include "shared_data.h"

extern char** environ;

namespace soupuv::test {
namespace fs = std::filesystem;

fs::path fresh_dir(const std::string& name) {
  fs::path p = fs::path(SOUPUV_BINARY_DIR) / "test-tmp" / "server" / (name + "-" + std::to_string(getpid()));
  fs::remove_all(p);
  fs::create_directories(p);
  return p;
}

std::string read_bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

std::string shared_data(const std::string& rel) { return soupuv_test::shared_data_dir() + "/" + rel; }

bool cli_available() { return std::string(SOUPUV_CLI_BIN).size() > 0 && access(SOUPUV_CLI_BIN, X_OK) == 0; }

ServerProcess::ServerProcess(fs::path data_dir, std::vector<std::string> args, std::vector<std::string> env) {
  // SOUPUV_TEST_SERVER_BIN runs the black-box tests against another build
  // (e.g. the previous commit's server, to see a new test fail there).
  const char* other = std::getenv("SOUPUV_TEST_SERVER_BIN");
  std::vector<std::string> argv = {other && *other ? other : SOUPUV_SERVER_BIN, "--host", "127.0.0.1", "--port", "0",
                                   "--data-dir", data_dir.string()};
  argv.insert(argv.end(), args.begin(), args.end());
  std::vector<std::string> envs;
  for (char** e = environ; *e; ++e) envs.emplace_back(*e);
  envs.insert(envs.end(), env.begin(), env.end());
  std::vector<char*> a, e;
  for (auto& s : argv) a.push_back(s.data());
  a.push_back(nullptr);
  for (auto& s : envs) e.push_back(s.data());
  e.push_back(nullptr);
  int fds[2];
  if (pipe2(fds, O_CLOEXEC) != 0) throw std::runtime_error("pipe");
  pid_ = fork();
  if (pid_ == 0) {
    dup2(fds[1], 2);
    int devnull = open("/dev/null", O_RDWR);
    dup2(devnull, 0);
    dup2(devnull, 1);
    execve(a[0], a.data(), e.data());
    _exit(127);
  }
  close(fds[1]);
  err_fd_ = fds[0];
  reader_ = std::thread([this] {
    char buf[4096];
    for (;;) {
      ssize_t n = read(err_fd_, buf, sizeof buf);
      if (n <= 0) break;
      std::lock_guard lock(mu_);
      log_.append(buf, size_t(n));
    }
  });
  static const std::regex port_re("\"msg\":\"listening\",\"port\":([0-9]+)");
  auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (std::chrono::steady_clock::now() < deadline) {
    {
      std::lock_guard lock(mu_);
      std::smatch m;
      if (std::regex_search(log_, m, port_re)) {
        port_ = std::stoi(m[1]);
        break;
      }
    }
    int status;
    if (waitpid(pid_, &status, WNOHANG) == pid_) {
      pid_ = -1;
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  if (port_ == 0) {
    // No destructor runs for a constructor that throws: end the process and
    // the reader here (a joinable thread member would std::terminate), so
    // the message has everything the server said.
    if (pid_ > 0) kill_hard();
    reader_.join();
    close(err_fd_);
    throw std::runtime_error("server did not start: " + log());
  }
}

httplib::MultipartFormDataItems two_sided_plane_parts(const std::string& params) {
  const std::string dir = shared_data("gltf/TwoSidedPlane/");
  return {
      {"file", read_bytes(dir + "TwoSidedPlane.gltf"), "TwoSidedPlane.gltf", "model/gltf+json"},
      {"files", read_bytes(dir + "TwoSidedPlane.bin"), "TwoSidedPlane.bin", "application/octet-stream"},
      {"files", read_bytes(dir + "TwoSidedPlane_BaseColor.png"), "TwoSidedPlane_BaseColor.png", "image/png"},
      {"params", params, "", "application/json"},
  };
}

ServerProcess::~ServerProcess() {
  if (pid_ > 0) terminate();
  if (reader_.joinable()) reader_.join();
  if (err_fd_ >= 0) close(err_fd_);
}

void ServerProcess::kill_hard() {
  if (pid_ <= 0) return;
  ::kill(pid_, SIGKILL);
  int status;
  waitpid(pid_, &status, 0);
  pid_ = -1;
}

int ServerProcess::terminate() {
  if (pid_ <= 0) return -1;
  ::kill(pid_, SIGTERM);
  int status = 0;
  for (int i = 0; i < 300; ++i) {  // 30 s, then force
    if (waitpid(pid_, &status, WNOHANG) == pid_) {
      pid_ = -1;
      return status;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  kill_hard();
  return -1;
}

std::string ServerProcess::log() const {
  std::lock_guard lock(mu_);
  return log_;
}

httplib::Client ServerProcess::client() const {
  httplib::Client c("127.0.0.1", port_);
  c.set_read_timeout(30, 0);
  c.set_write_timeout(30, 0);
  return c;
}

std::string read_until_close(int fd, int timeout_ms) {
  std::string out;
  auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
  while (std::chrono::steady_clock::now() < deadline) {
    pollfd p{fd, POLLIN, 0};
    if (poll(&p, 1, 50) <= 0) continue;
    char buf[4096];
    ssize_t n = recv(fd, buf, sizeof buf, 0);
    if (n <= 0) break;
    out.append(buf, size_t(n));
  }
  return out;
}

int loopback_connect(int port) {
  int fd = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return -1;
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(uint16_t(port));
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
    close(fd);
    return -1;
  }
  return fd;
}

std::string raw_exchange(int port, const std::string& request, int timeout_ms) {
  const int fd = loopback_connect(port);
  if (fd < 0) return "";
  size_t sent = 0;
  while (sent < request.size()) {
    ssize_t n = send(fd, request.data() + sent, request.size() - sent, MSG_NOSIGNAL);
    if (n <= 0) break;
    sent += size_t(n);
  }
  std::string out = read_until_close(fd, timeout_ms);
  close(fd);
  return out;
}

int status_of(const std::string& raw) {
  if (raw.rfind("HTTP/1.1 ", 0) != 0 || raw.size() < 12) return 0;
  return std::stoi(raw.substr(9, 3));
}

httplib::Result submit(httplib::Client& c, const std::string& bytes, const std::string& content_type,
                       const std::string& query, const httplib::Headers& headers) {
  return c.Post(("/v1/jobs" + query).c_str(), headers, bytes, content_type.c_str());
}

nlohmann::json wait_finished(httplib::Client& c, const std::string& id, double timeout_s) {
  auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  nlohmann::json last;
  while (std::chrono::steady_clock::now() < deadline) {
    auto r = c.Get(("/v1/jobs/" + id).c_str());
    if (r && r->status == 200) {
      last = nlohmann::json::parse(r->body);
      std::string s = last["state"];
      if (s == "succeeded" || s == "failed" || s == "canceled") return last;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return last;
}

nlohmann::json wait_state(httplib::Client& c, const std::string& id, const std::string& state, double timeout_s) {
  auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  nlohmann::json j;
  while (std::chrono::steady_clock::now() < deadline) {
    auto r = c.Get(("/v1/jobs/" + id).c_str());
    if (r && r->status == 200) {
      j = nlohmann::json::parse(r->body);
      if (j["state"] == state) return j;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return j;
}

std::unique_ptr<ServerProcess> with_double(const std::string& name, const std::string& mode,
                                           std::vector<std::string> args, const std::string& seconds,
                                           std::vector<std::string> env) {
  std::vector<std::string> a = {"--worker-bin", SOUPUV_WORKER_DOUBLE, "--validate-uploads", "false", "--worker-env",
                                kDoubleEnv};
  a.insert(a.end(), args.begin(), args.end());
  env.push_back("SOUPUV_TEST_WORKER_MODE=" + mode);
  env.push_back("SOUPUV_TEST_WORKER_SECONDS=" + seconds);
  return std::make_unique<ServerProcess>(fresh_dir(name), a, env);
}

std::string submit_box(httplib::Client& c, const httplib::Headers& headers) {
  auto r = submit(c, read_bytes(shared_data("gltf/Box.glb")), "model/gltf-binary", "", headers);
  if (!r || r->status != 202) return "";
  return nlohmann::json::parse(r->body)["id"];
}

}  // namespace soupuv::test
