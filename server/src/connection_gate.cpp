#include "soupuv/server/connection_gate.h"

#include <fcntl.h>
#include <sys/epoll.h>
#include <sys/eventfd.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace soupuv::server {
namespace {

using Clock = std::chrono::steady_clock;

void set_nonblocking(int fd) { fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) | O_NONBLOCK); }

size_t count_lines(const std::string& s, size_t end) { return size_t(std::count(s.begin(), s.begin() + end, '\n')); }

// Where a complete head ends (its blank line), or npos.
size_t head_end(const std::string& b) { return std::min(b.find("\r\n\r\n"), b.find("\n\n")); }

}  // namespace

bool ConnectionGate::head_complete(const std::string& b) { return head_end(b) != std::string::npos; }

ConnectionGate::ConnectionGate(Limits limits, Dispatch dispatch)
    : limits_(limits), dispatch_(std::move(dispatch)) {
  epoll_fd_ = epoll_create1(EPOLL_CLOEXEC);
  wake_fd_ = eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK);
  if (epoll_fd_ < 0 || wake_fd_ < 0) throw std::runtime_error(std::string("connection gate: ") + std::strerror(errno));
  epoll_event ev{};
  ev.events = EPOLLIN;
  ev.data.fd = wake_fd_;
  epoll_ctl(epoll_fd_, EPOLL_CTL_ADD, wake_fd_, &ev);
  thread_ = std::thread([this] { loop(); });
}

ConnectionGate::~ConnectionGate() {
  stop();
  close(wake_fd_);
  close(epoll_fd_);
}

void ConnectionGate::wait_for_head(int fd, std::string buffered, size_t served) {
  {
    std::lock_guard lock(mu_);
    if (!stopped_) {
      incoming_.push_back({fd, std::move(buffered), served, false});
      uint64_t one = 1;
      ssize_t ignored = write(wake_fd_, &one, sizeof one);
      (void)ignored;
      return;
    }
  }
  close(fd);
}

void ConnectionGate::linger_and_close(int fd) {
  {
    std::lock_guard lock(mu_);
    if (!stopped_) {
      incoming_.push_back({fd, {}, 0, true});
      uint64_t one = 1;
      ssize_t ignored = write(wake_fd_, &one, sizeof one);
      (void)ignored;
      return;
    }
  }
  close(fd);
}

void ConnectionGate::stop() {
  {
    std::lock_guard lock(mu_);
    if (stopped_) return;
    stopped_ = true;
    uint64_t one = 1;
    ssize_t ignored = write(wake_fd_, &one, sizeof one);
    (void)ignored;
  }
  if (thread_.joinable()) thread_.join();
  for (auto& [fd, c] : conns_) close(fd);
  conns_.clear();
  for (auto& in : incoming_) close(in.fd);
  incoming_.clear();
}

void ConnectionGate::adopt(Incoming in) {
  set_nonblocking(in.fd);
  Conn c;
  c.served = in.served;
  c.lingering = in.linger;
  if (in.linger) {
    shutdown(in.fd, SHUT_WR);  // the answer is out; tell the client we are done
    c.deadline = Clock::now() + limits_.linger_timeout;
  } else {
    c.buffered = std::move(in.buffered);
    // A connection with nothing buffered is idle (keep-alive) until its first byte.
    c.deadline = Clock::now() + (c.buffered.empty() ? limits_.idle_timeout : limits_.head_timeout);
    if (head_complete(c.buffered)) {  // pipelined: the next head is already here
      dispatch_(in.fd, std::move(c.buffered), c.served);
      return;
    }
  }
  epoll_event ev{};
  ev.events = EPOLLIN | EPOLLRDHUP;
  ev.data.fd = in.fd;
  if (epoll_ctl(epoll_fd_, EPOLL_CTL_ADD, in.fd, &ev) != 0) {
    close(in.fd);
    return;
  }
  conns_[in.fd] = std::move(c);
}

void ConnectionGate::close_conn(int fd) {
  epoll_ctl(epoll_fd_, EPOLL_CTL_DEL, fd, nullptr);
  close(fd);
  conns_.erase(fd);
}

void ConnectionGate::refuse(int fd, Conn& c, int status, const char* slug, const char* detail) {
  // Written here, on a non-blocking socket with an empty send buffer: a few
  // hundred bytes always fit.
  const std::string body = std::string("{\"type\":\"/problems/") + slug + "\",\"title\":\"" +
                           (status == 408 ? "Request Timeout" : "Request Header Fields Too Large") +
                           "\",\"status\":" + std::to_string(status) + ",\"detail\":\"" + detail + "\"}";
  const std::string res = "HTTP/1.1 " + std::to_string(status) +
                          (status == 408 ? " Request Timeout" : " Request Header Fields Too Large") +
                          "\r\nContent-Type: application/problem+json\r\nContent-Length: " +
                          std::to_string(body.size()) + "\r\nConnection: close\r\n\r\n" + body;
  ssize_t ignored = send(fd, res.data(), res.size(), MSG_NOSIGNAL);
  (void)ignored;
  shutdown(fd, SHUT_WR);
  c.lingering = true;
  c.buffered.clear();
  c.buffered.shrink_to_fit();
  c.deadline = Clock::now() + limits_.linger_timeout;
}

void ConnectionGate::on_readable(int fd, Conn& c) {
  char buf[8192];
  for (;;) {
    // A head is read no further than its limit (+1 to notice the excess).
    if (!c.lingering && c.buffered.size() > limits_.max_head_bytes)  // e.g. a huge pipelined leftover
      return refuse(fd, c, 431, "header-too-large", "the request head is larger than the server accepts");
    size_t want = c.lingering ? sizeof buf : std::min(sizeof buf, limits_.max_head_bytes + 1 - c.buffered.size());
    ssize_t n = recv(fd, buf, want, 0);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) return;
    if (n <= 0) {  // peer closed or error
      close_conn(fd);
      return;
    }
    if (c.lingering) continue;  // dropped
    if (c.buffered.empty()) c.deadline = Clock::now() + limits_.head_timeout;  // a head has begun
    c.buffered.append(buf, size_t(n));
    if (const size_t end = head_end(c.buffered); end != std::string::npos) {
      if (count_lines(c.buffered, end) > limits_.max_head_lines)
        return refuse(fd, c, 431, "header-too-large", "too many header lines");
      epoll_ctl(epoll_fd_, EPOLL_CTL_DEL, fd, nullptr);
      std::string bytes = std::move(c.buffered);
      const size_t served = c.served;
      conns_.erase(fd);
      dispatch_(fd, std::move(bytes), served);
      return;
    }
    if (c.buffered.size() > limits_.max_head_bytes || count_lines(c.buffered, c.buffered.size()) > limits_.max_head_lines)
      return refuse(fd, c, 431, "header-too-large", "the request head is larger than the server accepts");
  }
}

void ConnectionGate::loop() {
  epoll_event events[64];
  for (;;) {
    std::vector<Incoming> in;
    {
      std::lock_guard lock(mu_);
      if (stopped_) return;
      in.swap(incoming_);
    }
    for (auto& i : in) adopt(std::move(i));
    // Wake for the nearest deadline (at most 100 ms away, to notice stop()).
    auto now = Clock::now();
    auto next = now + std::chrono::milliseconds(100);
    for (const auto& [fd, c] : conns_) next = std::min(next, c.deadline);
    int wait_ms = int(std::max<int64_t>(0, std::chrono::duration_cast<std::chrono::milliseconds>(next - now).count()));
    int n = epoll_wait(epoll_fd_, events, 64, wait_ms);
    for (int i = 0; i < n; ++i) {
      int fd = events[i].data.fd;
      if (fd == wake_fd_) {
        uint64_t v;
        ssize_t ignored = read(wake_fd_, &v, sizeof v);
        (void)ignored;
        continue;
      }
      auto it = conns_.find(fd);
      if (it != conns_.end()) on_readable(fd, it->second);
    }
    now = Clock::now();
    std::vector<int> expired;
    for (const auto& [fd, c] : conns_)
      if (c.deadline <= now) expired.push_back(fd);
    for (int fd : expired) {
      Conn& c = conns_[fd];
      if (!c.lingering && !c.buffered.empty())
        refuse(fd, c, 408, "request-timeout", "the request head did not arrive in time");
      else
        close_conn(fd);  // idle keep-alive, or lingering done
    }
  }
}

}  // namespace soupuv::server
