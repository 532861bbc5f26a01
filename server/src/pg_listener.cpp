#include "soupuv/server/pg_listener.h"

#include <libpq-fe.h>
#include <poll.h>

#include <chrono>

#include "soupuv/server/log.h"
#include "soupuv/server/pg_connection.h"
#include "soupuv/server/pg_job_store.h"

namespace soupuv::server {

PgListener::PgListener(std::string url, Handler handler) : url_(std::move(url)), handler_(std::move(handler)) {}

PgListener::~PgListener() { stop(); }

void PgListener::start() { thread_ = std::thread([this] { loop(); }); }

void PgListener::stop() {
  stopping_ = true;
  if (thread_.joinable()) thread_.join();
}

void PgListener::loop() {
  PGconn* conn = nullptr;
  auto drop = [&] {
    if (conn) PQfinish(conn);
    conn = nullptr;
    connected_ = false;
  };
  while (!stopping_) {
    if (!conn) {
      conn = PQconnectdb(url_.c_str());
      const std::string listen = std::string("LISTEN ") + kJobsChannel + "; LISTEN " + kCancelChannel;
      PGresult* r = PQstatus(conn) == CONNECTION_OK ? PQexec(conn, listen.c_str()) : nullptr;
      const bool ok = r && PQresultStatus(r) == PGRES_COMMAND_OK;
      PQclear(r);
      if (!ok) {
        drop();
        for (int i = 0; i < 10 && !stopping_; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(100));
        continue;
      }
      connected_ = true;
      // Whatever was notified while this connection was down: wake the
      // workers once so they look at the queue.
      handler_(kJobsChannel, "");
    }
    // Wait for the socket at most 200 ms, so stop() is honoured quickly.
    pollfd p{PQsocket(conn), POLLIN, 0};
    const int n = ::poll(&p, 1, 200);
    if (n < 0 && errno != EINTR) {
      drop();
      continue;
    }
    if (n > 0 && (!PQconsumeInput(conn) || PQstatus(conn) != CONNECTION_OK)) {
      log::warn("database notification connection lost; reconnecting", {{"error", PQerrorMessage(conn)}});
      drop();
      continue;
    }
    while (PGnotify* note = PQnotifies(conn)) {
      const std::string channel = note->relname, payload = note->extra ? note->extra : "";
      PQfreemem(note);
      try {
        handler_(channel, payload);
      } catch (const std::exception& e) {
        log::warn("notification handler failed", {{"error", e.what()}});
      }
    }
  }
  drop();
}

}  // namespace soupuv::server
