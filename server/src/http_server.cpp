// HttpServer: see http_server.h. One request = one task on the HTTP pool, so
// a thread_local flag is enough to tie "close after this request" to the
// connection being served.
#include "soupuv/server/http_server.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <mutex>
#include <string>

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

// A plain-socket httplib::Stream with read/write timeouts and a read buffer
// that starts with the bytes the gate already read (the request head, maybe
// more); what is left in it after a request goes back to the gate. A body
// that trickles slower than the rate floor is cut off.
class ConnectionStream final : public httplib::Stream {
 public:
  ConnectionStream(socket_t sock, int read_ms, int write_ms, std::string buffered, double min_rate, double grace_s)
      : sock_(sock), read_ms_(read_ms), write_ms_(write_ms), buf_(std::move(buffered)), min_rate_(min_rate),
        grace_s_(grace_s), started_(std::chrono::steady_clock::now()) {}

  // Unread bytes (a pipelined next request), handed back to the gate.
  std::string take_buffered() { return buf_.substr(begin_); }

  bool is_readable() const override { return begin_ < buf_.size() || wait_for(sock_, POLLIN, read_ms_); }
  bool is_writable() const override { return wait_for(sock_, POLLOUT, write_ms_); }

  ssize_t read(char* ptr, size_t size) override {
    if (begin_ == buf_.size()) {
      if (too_slow() || !wait_for(sock_, POLLIN, read_ms_)) return -1;
      buf_.clear();
      begin_ = 0;
      if (size >= kChunk) {  // large reads bypass the buffer
        ssize_t n = recv_some(ptr, size);
        if (n > 0) from_socket_ += size_t(n);
        return n;
      }
      buf_.resize(kChunk);
      ssize_t n = recv_some(buf_.data(), kChunk);
      buf_.resize(n > 0 ? size_t(n) : 0);
      if (n <= 0) return n;
      from_socket_ += size_t(n);
    }
    size_t n = std::min(size, buf_.size() - begin_);
    std::memcpy(ptr, buf_.data() + begin_, n);
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

  // Past the grace period, a request whose bytes average less than the floor
  // is a slow-body attack (or a link too slow to be served): stop reading.
  bool too_slow() const {
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count();
    return s > grace_s_ && double(from_socket_) < min_rate_ * s;
  }

  static constexpr size_t kChunk = 4096;
  socket_t sock_;
  int read_ms_, write_ms_;
  std::string buf_;
  size_t begin_ = 0;
  size_t from_socket_ = 0;
  double min_rate_, grace_s_;
  std::chrono::steady_clock::time_point started_;
};

}  // namespace

void close_connection_after(httplib::Response& res) {
  if (!t_close_after_request) res.set_header("Connection", "close");
  t_close_after_request = true;
}

HttpServer::HttpServer() {
  // httplib's own queue only hands accepted sockets to the gate.
  new_task_queue = [] { return new httplib::ThreadPool(2); };
  set_limits(Limits{});
}

HttpServer::~HttpServer() { close_connections(); }

void HttpServer::set_limits(const Limits& limits) {
  close_connections();
  gate_.reset();
  pool_.reset();
  closed_ = false;
  limits_ = limits;
  pool_ = std::make_unique<httplib::ThreadPool>(limits_.worker_threads);
  gate_ = std::make_unique<ConnectionGate>(limits_.gate, [this](int fd, std::string bytes, size_t served) {
    pool_->enqueue([this, fd, b = std::move(bytes), served]() mutable { serve(fd, std::move(b), served); });
  });
}

bool HttpServer::set_listen_backlog(int backlog) { return ::listen(svr_sock_, backlog) == 0; }

bool HttpServer::process_and_close_socket(socket_t sock) {
  if (!gate_) {  // set_limits was not called: nothing can serve it
    close(sock);
    return false;
  }
  // Answers go out as headers + body in two writes: without NODELAY, Nagle
  // and the client's delayed ACK add ~40 ms to each (set here, on the
  // accepted socket, whatever httplib's accept path does).
  int one = 1;
  setsockopt(sock, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
  gate_->wait_for_head(sock);
  return true;
}

// One request on an HTTP thread; then the connection goes back to the gate
// (keep-alive), is closed, or lingers (a refusal that may have left a body unread).
void HttpServer::serve(int fd, std::string buffered, size_t served) {
  fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) & ~O_NONBLOCK);
  ConnectionStream strm(fd, timeout_ms(read_timeout_sec_, read_timeout_usec_),
                        timeout_ms(write_timeout_sec_, write_timeout_usec_), std::move(buffered),
                        limits_.min_body_rate, limits_.body_grace_seconds);
  t_close_after_request = false;
  bool connection_closed = false;
  const bool last = served + 1 >= keep_alive_max_count_ || svr_sock_ == INVALID_SOCKET;
  const bool ok = process_request(strm, last, connection_closed, nullptr);
  const bool unread = t_close_after_request || !ok;
  t_close_after_request = false;
  if (unread) {
    gate_->linger_and_close(fd);
  } else if (connection_closed || last) {
    shutdown(fd, SHUT_RDWR);
    close(fd);
  } else {
    gate_->wait_for_head(fd, strm.take_buffered(), served + 1);
  }
}

// The gate and the pool stay allocated until the destructor: httplib's
// accept hand-off may still be finishing on another thread after stop(), and
// a stopped gate just closes what it is handed.
void HttpServer::close_connections() {
  std::lock_guard lock(close_mu_);
  if (closed_) return;
  closed_ = true;
  if (gate_) gate_->stop();  // later hand-backs close their fd at once
  if (pool_) pool_->shutdown();
}

}  // namespace soupuv::server
