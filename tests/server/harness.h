// Starts a real soupuv-server process on 127.0.0.1 (port 0: the kernel picks a
// free one; the harness reads it from the "listening" log line) with a fresh
// data directory, and offers raw-socket and httplib clients against it.
#pragma once

#include <sys/types.h>

#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <httplib.h>
#include <nlohmann/json.hpp>

namespace soupuv::test {

std::filesystem::path fresh_dir(const std::string& name);  // under the build dir
std::string read_bytes(const std::filesystem::path& p);
std::string shared_data(const std::string& rel);           // SOUPUV_SHARED_DATA/rel
// A folder upload of the shared TwoSidedPlane sample: the .gltf, its .bin and
// its base-colour image as multipart parts, with `params` (JSON) last.
httplib::MultipartFormDataItems two_sided_plane_parts(const std::string& params);
bool cli_available();                                      // the real soupuv CLI was built

class ServerProcess {
 public:
  // `args` are extra flags; `env` extra NAME=VALUE entries.
  ServerProcess(std::filesystem::path data_dir, std::vector<std::string> args,
                std::vector<std::string> env = {});
  ~ServerProcess();
  int port() const { return port_; }
  pid_t pid() const { return pid_; }
  void kill_hard();           // SIGKILL, reaped
  int terminate();            // SIGTERM, waits; exit status
  std::string log() const;    // stderr so far
  httplib::Client client() const;

 private:
  pid_t pid_ = -1;
  int port_ = 0;
  int err_fd_ = -1;
  std::thread reader_;
  mutable std::mutex mu_;
  std::string log_;
};

// A TCP connection to 127.0.0.1:port (close-on-exec), or -1.
int loopback_connect(int port);

// Everything read from fd until the peer closes or `timeout_ms` passes.
std::string read_until_close(int fd, int timeout_ms);

// Sends `request` as is and returns everything read until the peer closes or
// `timeout_ms` passes.
std::string raw_exchange(int port, const std::string& request, int timeout_ms = 3000);
int status_of(const std::string& raw_response);

// Submits a file with an explicit Content-Type; returns (status, body JSON or null).
httplib::Result submit(httplib::Client& c, const std::string& bytes, const std::string& content_type,
                       const std::string& query = "", const httplib::Headers& headers = {});
// Polls GET /v1/jobs/{id} until a finished state or timeout; returns the last job JSON.
nlohmann::json wait_finished(httplib::Client& c, const std::string& id, double timeout_s = 60);

// Polls GET /v1/jobs/{id} until its state is `state` or timeout; returns the last job JSON.
nlohmann::json wait_state(httplib::Client& c, const std::string& id, const std::string& state,
                          double timeout_s = 20);

// The variables worker_double.sh reads, which the server must pass to it
// (workers get a minimal environment: --worker-env).
inline constexpr const char* kDoubleEnv =
    "SOUPUV_TEST_WORKER_MODE,SOUPUV_TEST_WORKER_SECONDS,SOUPUV_TEST_ESCAPE_READ,SOUPUV_TEST_ESCAPE_WRITE";

// A server whose worker is tests/server/worker_double.sh in `mode` (uploads not
// inspected), each job lasting `seconds` in the modes that sleep.
std::unique_ptr<ServerProcess> with_double(const std::string& name, const std::string& mode,
                                           std::vector<std::string> args = {}, const std::string& seconds = "30",
                                           std::vector<std::string> env = {});
// Submits the shared Box.glb; the job id, or "" if not accepted.
std::string submit_box(httplib::Client& c, const httplib::Headers& headers = {});

}  // namespace soupuv::test
