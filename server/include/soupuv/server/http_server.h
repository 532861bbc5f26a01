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
#pragma once

#include <httplib.h>

namespace soupuv::server {

class HttpServer : public httplib::Server {
 public:
  bool set_listen_backlog(int backlog);

 private:
  bool process_and_close_socket(socket_t sock) override;
};

// For the request being handled on this thread: answer with "Connection:
// close" (so clients and proxies do not reuse the connection) and do not read
// another request from it. Call whenever a request body may be left unread.
void close_connection_after(httplib::Response& res);

}  // namespace soupuv::server
