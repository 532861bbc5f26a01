// HttpServer: see http_server.h. One connection = one task on httplib's thread
// pool, so a thread_local flag is enough to tie "close after this request" to
// the connection being served.
#include "soupuv/server/http_server.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>

namespace soupuv::server {
namespace {

thread_local bool t_close_after_request = false;

int timeout_ms(time_t sec, time_t usec) { return int(sec * 1000 + usec / 1000); }

bool wait_for(socket_t sock, short events, int ms) {
  pollfd p{sock, events, 0};
  for (;;) {
    int n = poll(&p, 1, ms);
    if (n < 0 && errno == EINTR) continue;
    return n > 0 && (p.revents & (events | POLLHUP | POLLERR)) != 0;
  }
}

void address_of(const sockaddr_storage& a, std::string& ip, int& port) {
  char buf[INET6_ADDRSTRLEN] = {};
  if (a.ss_family == AF_INET) {
    auto* v4 = reinterpret_cast<const sockaddr_in*>(&a);
    inet_ntop(AF_INET, &v4->sin_addr, buf, sizeof buf);
    port = ntohs(v4->sin_port);
  } else if (a.ss_family == AF_INET6) {
    auto* v6 = reinterpret_cast<const sockaddr_in6*>(&a);
    inet_ntop(AF_INET6, &v6->sin6_addr, buf, sizeof buf);
    port = ntohs(v6->sin6_port);
  }
  ip = buf;
}

// A plain-socket httplib::Stream with read/write timeouts and a small read
// buffer (httplib reads header lines a byte at a time).
class ConnectionStream final : public httplib::Stream {
 public:
  ConnectionStream(socket_t sock, int read_ms, int write_ms) : sock_(sock), read_ms_(read_ms), write_ms_(write_ms) {}

  bool is_readable() const override { return begin_ < end_ || wait_for(sock_, POLLIN, read_ms_); }
  bool is_writable() const override { return wait_for(sock_, POLLOUT, write_ms_); }

  ssize_t read(char* ptr, size_t size) override {
    if (begin_ == end_) {
      if (!wait_for(sock_, POLLIN, read_ms_)) return -1;
      if (size >= sizeof buf_) return recv_some(ptr, size);  // large reads bypass the buffer
      ssize_t n = recv_some(buf_, sizeof buf_);
      if (n <= 0) return n;
      begin_ = 0;
      end_ = size_t(n);
    }
    size_t n = std::min(size, end_ - begin_);
    std::memcpy(ptr, buf_ + begin_, n);
    begin_ += n;
    return ssize_t(n);
  }

  ssize_t write(const char* ptr, size_t size) override {
    if (!is_writable()) return -1;
    for (;;) {
      ssize_t n = send(sock_, ptr, size, MSG_NOSIGNAL);
      if (n < 0 && errno == EINTR) continue;
      return n;
    }
  }

  void get_remote_ip_and_port(std::string& ip, int& port) const override {
    sockaddr_storage a{};
    socklen_t len = sizeof a;
    if (getpeername(sock_, reinterpret_cast<sockaddr*>(&a), &len) == 0) address_of(a, ip, port);
  }
  void get_local_ip_and_port(std::string& ip, int& port) const override {
    sockaddr_storage a{};
    socklen_t len = sizeof a;
    if (getsockname(sock_, reinterpret_cast<sockaddr*>(&a), &len) == 0) address_of(a, ip, port);
  }
  socket_t socket() const override { return sock_; }

 private:
  ssize_t recv_some(char* p, size_t n) {
    for (;;) {
      ssize_t got = recv(sock_, p, n, 0);
      if (got < 0 && errno == EINTR) continue;
      return got;
    }
  }

  socket_t sock_;
  int read_ms_, write_ms_;
  char buf_[4096];
  size_t begin_ = 0, end_ = 0;
};

}  // namespace

void close_connection_after(httplib::Response& res) {
  if (!t_close_after_request) res.set_header("Connection", "close");
  t_close_after_request = true;
}

bool HttpServer::set_listen_backlog(int backlog) { return ::listen(svr_sock_, backlog) == 0; }

// 0.11.4's loop, plus the close flag: wait (keep-alive timeout) for the next
// request, serve it, stop after max_count requests, on error, when the client
// asked to close, or when a handler left a body unread.
bool HttpServer::process_and_close_socket(socket_t sock) {
  ConnectionStream strm(sock, timeout_ms(read_timeout_sec_, read_timeout_usec_),
                        timeout_ms(write_timeout_sec_, write_timeout_usec_));
  bool ok = false;
  size_t left = keep_alive_max_count_;
  const auto idle_until = [this] {
    return std::chrono::steady_clock::now() + std::chrono::seconds(keep_alive_timeout_sec_);
  };
  for (auto deadline = idle_until(); left > 0 && svr_sock_ != INVALID_SOCKET; deadline = idle_until()) {
    // Wait for the next request in short slices, so that stop() is noticed.
    bool readable = strm.is_readable();
    while (!readable && svr_sock_ != INVALID_SOCKET && std::chrono::steady_clock::now() < deadline)
      readable = wait_for(sock, POLLIN, 100);
    if (!readable) break;
    t_close_after_request = false;
    bool connection_closed = false;
    ok = process_request(strm, left == 1, connection_closed, nullptr);
    if (!ok || connection_closed || t_close_after_request) break;
    --left;
  }
  t_close_after_request = false;
  shutdown(sock, SHUT_RDWR);
  close(sock);
  return ok;
}

}  // namespace soupuv::server
