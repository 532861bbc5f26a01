#include "soupuv/server/pg_connection.h"

#include <charconv>
#include <cstdio>
#include <stdexcept>

#include "soupuv/server/storage.h"

namespace soupuv::server {

int64_t PgResult::integer(int row, int col) const {
  const std::string v = text(row, col);
  int64_t out = 0;
  std::from_chars(v.data(), v.data() + v.size(), out);
  return out;
}

double PgResult::real(int row, int col) const {
  const std::string v = text(row, col);
  return v.empty() ? 0.0 : std::strtod(v.c_str(), nullptr);
}

int64_t PgResult::affected() const {
  const char* n = PQcmdTuples(r_);
  return n && *n ? std::strtoll(n, nullptr, 10) : 0;
}

PgParam pg_num(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return PgParam(std::string(buf));
}

PgParam pg_int(int64_t v) { return PgParam(std::to_string(v)); }

PgConnection::PgConnection(std::string url, std::string session_sql)
    : url_(std::move(url)), session_sql_(std::move(session_sql)) {}

PgConnection::~PgConnection() {
  if (conn_) PQfinish(conn_);
}

void PgConnection::reset() {
  if (conn_) PQfinish(conn_);
  conn_ = nullptr;
  prepared_.clear();
}

PGconn* PgConnection::raw() {
  if (conn_ && PQstatus(conn_) == CONNECTION_OK) return conn_;
  reset();
  conn_ = PQconnectdb(url_.c_str());
  if (PQstatus(conn_) != CONNECTION_OK) {
    std::string msg = conn_ ? PQerrorMessage(conn_) : "out of memory";
    while (!msg.empty() && (msg.back() == '\n' || msg.back() == ' ')) msg.pop_back();
    reset();
    throw StorageUnavailable("postgresql connect: " + msg);
  }
  // Times are unix seconds computed by the server (EXTRACT(EPOCH ...)), so the
  // session time zone never matters; statements are short, so a stuck one
  // (a lock held by a dead transaction) fails instead of holding a thread.
  PQclear(PQexec(conn_, "SET statement_timeout = '30s'; SET lock_timeout = '10s'; SET client_min_messages = warning"));
  if (!session_sql_.empty()) PQclear(PQexec(conn_, session_sql_.c_str()));
  return conn_;
}

PgResult PgConnection::run(const std::string& sql, const std::vector<PgParam>& params, bool binary_result) {
  PGconn* c = raw();
  std::vector<const char*> values(params.size());
  std::vector<int> lengths(params.size()), formats(params.size());
  for (size_t i = 0; i < params.size(); ++i) {
    values[i] = params[i].value ? params[i].value->data() : nullptr;
    lengths[i] = params[i].value ? int(params[i].value->size()) : 0;
    formats[i] = params[i].binary ? 1 : 0;
  }
  PgResult r;
  auto it = prepared_.find(sql);
  if (it == prepared_.end() && sql != "BEGIN" && sql != "COMMIT") {
    const std::string name = "s" + std::to_string(prepared_.size());
    PgResult p(PQprepare(c, name.c_str(), sql.c_str(), int(params.size()), nullptr));
    if (p.get() && PQresultStatus(p.get()) == PGRES_COMMAND_OK) it = prepared_.emplace(sql, name).first;
    else r = std::move(p);  // the same error the statement would give: reported below
  }
  if (it != prepared_.end())
    r = PgResult(PQexecPrepared(c, it->second.c_str(), int(params.size()), values.data(), lengths.data(),
                                formats.data(), binary_result ? 1 : 0));
  else if (!r.get())
    r = PgResult(PQexecParams(c, sql.c_str(), int(params.size()), nullptr, values.data(), lengths.data(),
                              formats.data(), binary_result ? 1 : 0));
  const auto status = r.get() ? PQresultStatus(r.get()) : PGRES_FATAL_ERROR;
  if (status == PGRES_COMMAND_OK || status == PGRES_TUPLES_OK) return r;
  std::string msg = r.get() ? PQresultErrorMessage(r.get()) : PQerrorMessage(c);
  while (!msg.empty() && (msg.back() == '\n' || msg.back() == ' ')) msg.pop_back();
  const char* st = r.get() ? PQresultErrorField(r.get(), PG_DIAG_SQLSTATE) : nullptr;
  const std::string sqlstate = st ? st : "";
  // Class 08 (connection exception), 57P0x (admin shutdown, crash shutdown,
  // cannot connect now), 53 (insufficient resources) and a dead socket are the
  // server's condition, not the statement's: StorageUnavailable.
  if (PQstatus(c) != CONNECTION_OK || sqlstate.rfind("08", 0) == 0 || sqlstate.rfind("57P", 0) == 0 ||
      sqlstate.rfind("53", 0) == 0 || sqlstate.empty()) {
    reset();
    throw StorageUnavailable("postgresql: " + msg);
  }
  throw PgError("postgresql: " + msg, sqlstate);
}

PgResult PgConnection::exec(const std::string& sql, const std::vector<PgParam>& params, bool binary_result) {
  if (in_transaction_) return run(sql, params, binary_result);
  try {
    return run(sql, params, binary_result);
  } catch (const StorageUnavailable&) {
    // One more time on a new connection: after a PostgreSQL restart every
    // pooled connection is dead once, and the statement itself was not run.
    // (A statement whose commit was lost with the connection may have run;
    // every write here is safe to repeat: conditioned on state and owner.)
    return run(sql, params, binary_result);
  }
}

void PgConnection::transaction(const std::function<void(PgConnection&)>& body) {
  exec("BEGIN");
  in_transaction_ = true;
  try {
    body(*this);
    in_transaction_ = false;
    exec("COMMIT");
  } catch (...) {
    in_transaction_ = false;
    if (conn_ && PQstatus(conn_) == CONNECTION_OK) PQclear(PQexec(conn_, "ROLLBACK"));
    throw;
  }
}

PgPool::PgPool(std::string url, int size, const std::string& session_sql) : url_(std::move(url)) {
  for (int i = 0; i < std::max(1, size); ++i) idle_.push_back(std::make_unique<PgConnection>(url_, session_sql));
}

PgPool::Lease PgPool::take() {
  std::unique_lock lock(mu_);
  cv_.wait(lock, [&] { return !idle_.empty(); });
  auto c = std::move(idle_.back());
  idle_.pop_back();
  return Lease(*this, std::move(c));
}

void PgPool::give_back(std::unique_ptr<PgConnection> c) {
  {
    std::lock_guard lock(mu_);
    idle_.push_back(std::move(c));
  }
  cv_.notify_one();
}

bool is_postgres_url(const std::string& url) {
  return url.rfind("postgresql://", 0) == 0 || url.rfind("postgres://", 0) == 0;
}

std::string redact_database_url(const std::string& url) {
  // scheme://user:password@host -> scheme://user:***@host
  const size_t scheme = url.find("://");
  if (scheme == std::string::npos) return "(not a URL)";
  const size_t at = url.find('@', scheme + 3);
  if (at == std::string::npos) return url;
  const size_t colon = url.find(':', scheme + 3);
  if (colon == std::string::npos || colon > at) return url;
  return url.substr(0, colon + 1) + "***" + url.substr(at);
}

}  // namespace soupuv::server
