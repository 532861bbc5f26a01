// httplib::Server with two fixes for Debian's cpp-httplib 0.11.4 (a compiled
// library, so its defaults cannot be changed by macros):
//
// 1. Listen backlog: 0.11.4 listens with a backlog of 5. A burst of new
//    connections overflows it, the kernel drops SYNs and clients retry only
//    after 1 s (measured: the old 1 s tail on status polls). Linux lets a
//    listening socket be given a new backlog by calling listen() again.
//
// 2. Keep-alive without request smuggling: 0.11.4 keeps a connection open
//    after a handler refused a request whose body it never read, so those
//    body bytes would be parsed as the next request. Handlers and guards call
//    close_connection_after(res); our connection loop (replacing
//    0.11.4's, same steps) then closes the socket instead of reading on.
//    Successful requests keep the connection (fewer TCP handshakes per poll).
//
// 3. Slow clients hold no HTTP thread: accepted connections go to a
//    ConnectionGate (connection_gate.h), an epoll thread that waits for each
//    request head (bounded in time and size) and lingers after refusals;
//    only a complete head is served, on this class's own pool of
//    `worker_threads` (httplib's task queue just hands sockets over). A
//    request body must keep arriving at min_body_rate after a grace period.
#pragma once

#include <httplib.h>

#include <memory>
#include <mutex>

#include "soupuv/server/connection_gate.h"

namespace soupuv::server {

class HttpServer : public httplib::Server {
 public:
  struct Limits {
    ConnectionGate::Limits gate;
    size_t worker_threads = 32;
    double min_body_rate = 1024;        // bytes/s a body must average ...
    double body_grace_seconds = 10;     // ... once it has taken this long
  };
  HttpServer();
  ~HttpServer() override;
  void set_limits(const Limits& limits);  // before listening (the constructor sets the defaults)
  bool set_listen_backlog(int backlog);
  // After stop(): closes the connections waiting in the gate and waits for
  // the requests being served.
  void close_connections();

 private:
  bool process_and_close_socket(socket_t sock) override;
  void serve(int fd, std::string buffered, size_t served);

  Limits limits_;
  std::unique_ptr<ConnectionGate> gate_;
  std::unique_ptr<httplib::ThreadPool> pool_;
  std::mutex close_mu_;
  bool closed_ = false;
};

// For the request being handled on this thread: answer with "Connection:
// close" (so clients and proxies do not reuse the connection) and do not read
// another request from it. Call whenever a request body may be left unread.
void close_connection_after(httplib::Response& res);

}  // namespace soupuv::server
