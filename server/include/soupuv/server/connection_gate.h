// The connection gate: one epoll thread that holds every connection while it
// is not being served — waiting for a request head, idle between keep-alive
// requests, or lingering after a refusal — so that no HTTP thread is held by
// a client that is slow (or malicious: slowloris) in sending its headers.
//
// A connection reaches an HTTP thread only with a complete request head in
// hand (at most max_head_bytes and max_head_lines, so httplib never buffers
// more); a head not complete within head_timeout is answered 408, one too
// large 431, and an idle keep-alive connection is closed after idle_timeout.
// Refusals close gracefully: the gate shuts down the sending side and reads
// (and drops) what the client still sends for up to linger_timeout, so the
// client reads its 4xx instead of a connection reset.
#pragma once

#include <chrono>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <unordered_map>
#include <vector>

namespace soupuv::server {

class ConnectionGate {
 public:
  struct Limits {
    std::chrono::milliseconds head_timeout{10000};   // first byte of a head to its end
    std::chrono::milliseconds idle_timeout{5000};    // keep-alive: between requests
    std::chrono::milliseconds linger_timeout{2000};  // draining after a refusal
    size_t max_head_bytes = 16384;
    size_t max_head_lines = 100;
  };
  // Called on the gate's thread with a connection whose `buffered` bytes hold
  // a complete request head (and maybe more); `served` counts its earlier requests.
  using Dispatch = std::function<void(int fd, std::string buffered, size_t served)>;

  ConnectionGate(Limits limits, Dispatch dispatch);
  ~ConnectionGate();
  ConnectionGate(const ConnectionGate&) = delete;
  ConnectionGate& operator=(const ConnectionGate&) = delete;

  // Thread-safe. The gate owns `fd` from here (closes it unless dispatched).
  void wait_for_head(int fd, std::string buffered = {}, size_t served = 0);
  // Thread-safe: half-close, drain for up to linger_timeout, close.
  void linger_and_close(int fd);
  // Closes every connection the gate holds and stops its thread; later
  // calls to wait_for_head / linger_and_close close the fd at once.
  void stop();

  // A request head in `bytes` is complete (blank line after the request line).
  static bool head_complete(const std::string& bytes);

 private:
  struct Conn {
    std::string buffered;
    size_t served = 0;
    bool lingering = false;
    std::chrono::steady_clock::time_point deadline;
  };
  struct Incoming {
    int fd;
    std::string buffered;
    size_t served;
    bool linger;
  };

  void loop();
  void adopt(Incoming in);
  void on_readable(int fd, Conn& c);
  void refuse(int fd, Conn& c, int status, const char* slug, const char* detail);
  void close_conn(int fd);

  Limits limits_;
  Dispatch dispatch_;
  int epoll_fd_ = -1;
  int wake_fd_ = -1;
  std::mutex mu_;
  std::vector<Incoming> incoming_;
  bool stopped_ = false;
  std::unordered_map<int, Conn> conns_;  // the gate thread's alone
  std::thread thread_;
};

}  // namespace soupuv::server
