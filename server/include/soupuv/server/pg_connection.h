// A small libpq (Debian's libpq-dev) layer for the PostgreSQL job and blob
// stores: a connection that reconnects, parameterised statements, a pool.
//
// Every failure of the server or the network is StorageUnavailable
// (storage.h), so the API answers it 503 + Retry-After and the supervisor
// retries it, exactly like a failing SQLite write. A statement that fails on
// a broken connection is retried once on a fresh one: that is what makes a
// PostgreSQL restart invisible to callers beyond a short wait.
#pragma once

#include <libpq-fe.h>

#include <condition_variable>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

namespace soupuv::server {

// One statement's result (owns the PGresult).
class PgResult {
 public:
  explicit PgResult(PGresult* r = nullptr) : r_(r) {}
  PgResult(PgResult&& o) noexcept : r_(o.r_) { o.r_ = nullptr; }
  PgResult& operator=(PgResult&& o) noexcept {
    std::swap(r_, o.r_);
    return *this;
  }
  ~PgResult() { PQclear(r_); }
  int rows() const { return PQntuples(r_); }
  bool null(int row, int col) const { return PQgetisnull(r_, row, col) != 0; }
  std::string text(int row, int col) const {
    return std::string(PQgetvalue(r_, row, col), size_t(PQgetlength(r_, row, col)));
  }
  int64_t integer(int row, int col) const;
  double real(int row, int col) const;
  bool boolean(int row, int col) const { return text(row, col) == "t"; }
  // Affected rows of an UPDATE/DELETE/INSERT.
  int64_t affected() const;
  PGresult* get() const { return r_; }

 private:
  PGresult* r_;
};

// A parameter: text, or binary bytes (bytea), or SQL NULL.
struct PgParam {
  std::optional<std::string> value;
  bool binary = false;
  PgParam() = default;  // NULL
  PgParam(std::string v) : value(std::move(v)) {}  // NOLINT: implicit on purpose, like a literal
  PgParam(const char* v) : value(std::string(v)) {}  // NOLINT
  static PgParam bytes(std::string v) {
    PgParam p(std::move(v));
    p.binary = true;
    return p;
  }
};
PgParam pg_num(double v);
PgParam pg_int(int64_t v);

class PgConnection {
 public:
  // `session_sql` runs on every new connection (e.g. SET synchronous_commit).
  explicit PgConnection(std::string url, std::string session_sql = "");  // connects lazily
  ~PgConnection();
  PgConnection(const PgConnection&) = delete;
  PgConnection& operator=(const PgConnection&) = delete;

  // Runs one statement. Throws StorageUnavailable when the server cannot be
  // reached (after one reconnect), PgError for a statement the server refused.
  PgResult exec(const std::string& sql, const std::vector<PgParam>& params = {}, bool binary_result = false);
  // BEGIN ... COMMIT around `body`; ROLLBACK if it throws. The transaction is
  // not retried on a broken connection (the body may have had effects the
  // caller must see fail), only the connection is renewed for the next call.
  void transaction(const std::function<void(PgConnection&)>& body);
  PGconn* raw();  // connected (throws StorageUnavailable if it cannot)
  void reset();   // drop the connection; the next use reconnects

 private:
  PgResult run(const std::string& sql, const std::vector<PgParam>& params, bool binary_result);
  std::string url_, session_sql_;
  PGconn* conn_ = nullptr;
  // Statements prepared on this connection (SQL -> name): the server parses
  // and plans each once per connection, not once per call.
  std::map<std::string, std::string> prepared_;
  bool in_transaction_ = false;
};

// A statement the server refused (constraint, syntax): the caller's bug or a
// condition it handles (SQLSTATE in `state`, e.g. 23505 unique_violation).
class PgError : public std::runtime_error {
 public:
  PgError(const std::string& what, std::string sqlstate) : std::runtime_error(what), state(std::move(sqlstate)) {}
  std::string state;
};

// A fixed set of connections shared by threads. A status poll takes one for
// a primary-key read, so the pool is sized for the HTTP threads that read
// plus the workers that write (PgJobStore's caller chooses).
class PgPool {
 public:
  PgPool(std::string url, int size, const std::string& session_sql = "");
  class Lease {
   public:
    Lease(PgPool& pool, std::unique_ptr<PgConnection> c) : pool_(pool), c_(std::move(c)) {}
    ~Lease() { pool_.give_back(std::move(c_)); }
    Lease(const Lease&) = delete;
    PgConnection* operator->() { return c_.get(); }
    PgConnection& operator*() { return *c_; }

   private:
    PgPool& pool_;
    std::unique_ptr<PgConnection> c_;
  };
  Lease take();
  const std::string& url() const { return url_; }

 private:
  void give_back(std::unique_ptr<PgConnection> c);
  std::string url_;
  std::mutex mu_;
  std::condition_variable cv_;
  std::vector<std::unique_ptr<PgConnection>> idle_;
};

// The URL without its password, for logs.
std::string redact_database_url(const std::string& url);
bool is_postgres_url(const std::string& url);

}  // namespace soupuv::server
