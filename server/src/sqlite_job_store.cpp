// JobStore on SQLite (Debian's libsqlite3) in WAL mode: readers (status polls)
// never wait for the writer, and a committed transaction survives SIGKILL and
// power loss (synchronous=FULL). A failed statement throws StorageUnavailable.
// One connection guarded by a mutex — job metadata writes are few and tiny
// compared with the pipeline, so this is never the bottleneck.
#include <sqlite3.h>

#include <mutex>
#include <stdexcept>

#include "soupuv/server/job_store.h"
#include "soupuv/server/storage.h"

namespace soupuv::server {
namespace {

class Stmt {
 public:
  Stmt(sqlite3* db, const char* sql) : db_(db) {
    if (sqlite3_prepare_v2(db, sql, -1, &s_, nullptr) != SQLITE_OK)
      throw std::runtime_error(std::string("sqlite prepare: ") + sqlite3_errmsg(db));
  }
  ~Stmt() { sqlite3_finalize(s_); }
  Stmt(const Stmt&) = delete;
  Stmt& operator=(const Stmt&) = delete;

  Stmt& bind(int i, const std::string& v) {
    sqlite3_bind_text(s_, i, v.data(), int(v.size()), SQLITE_TRANSIENT);
    return *this;
  }
  Stmt& bind(int i, double v) { sqlite3_bind_double(s_, i, v); return *this; }
  Stmt& bind(int i, int64_t v) { sqlite3_bind_int64(s_, i, v); return *this; }
  Stmt& bind(int i, int v) { sqlite3_bind_int64(s_, i, v); return *this; }
  Stmt& bind_null(int i) { sqlite3_bind_null(s_, i); return *this; }

  // True while a row is available.
  bool step() {
    int rc = sqlite3_step(s_);
    if (rc == SQLITE_ROW) return true;
    if (rc == SQLITE_DONE) return false;
    throw StorageUnavailable(std::string("sqlite step: ") + sqlite3_errmsg(db_));
  }
  int step_rc() { return sqlite3_step(s_); }
  std::string text(int c) const {
    auto p = sqlite3_column_text(s_, c);
    return p ? std::string(reinterpret_cast<const char*>(p), size_t(sqlite3_column_bytes(s_, c))) : "";
  }
  double real(int c) const { return sqlite3_column_double(s_, c); }
  int64_t integer(int c) const { return sqlite3_column_int64(s_, c); }
  bool is_null(int c) const { return sqlite3_column_type(s_, c) == SQLITE_NULL; }

 private:
  sqlite3* db_;
  sqlite3_stmt* s_ = nullptr;
};

constexpr const char* kColumns =
    "id, state, created_at, started_at, finished_at, stage, fraction, stage_seconds, error_code, "
    "error_status, error_detail, params, input_file, content_type, input_bytes, idem_key, "
    "request_hash, attempts, cancel_requested, outputs, seq, tenant, result_attempt";

// Idempotency keys are unique per tenant. The idem_key column (UNIQUE since
// the first schema) holds "tenant\nkey"; neither part can contain '\n'
// (validated at the API), and the tenant-less form is the key alone, as
// before tenants existed.
std::string stored_key(const std::string& tenant, const std::string& key) {
  return tenant.empty() ? key : tenant + "\n" + key;
}

Job read_job(const Stmt& s) {
  Job j;
  j.id = s.text(0);
  j.state = parse_job_state(s.text(1)).value_or(JobState::failed);
  j.created_at = s.real(2);
  j.started_at = s.real(3);
  j.finished_at = s.real(4);
  j.stage = s.text(5);
  j.fraction = s.real(6);
  j.stage_seconds = nlohmann::json::parse(s.text(7), nullptr, false);
  if (!j.stage_seconds.is_object()) j.stage_seconds = nlohmann::json::object();
  if (!s.is_null(8)) j.error = JobError{s.text(8), int(s.integer(9)), s.text(10)};
  j.params = nlohmann::json::parse(s.text(11), nullptr, false);
  if (!j.params.is_object()) j.params = nlohmann::json::object();
  j.input_file = s.text(12);
  j.content_type = s.text(13);
  j.input_bytes = s.integer(14);
  j.idempotency_key = s.text(15);
  if (auto nl = j.idempotency_key.find('\n'); nl != std::string::npos) j.idempotency_key.erase(0, nl + 1);
  j.request_hash = s.text(16);
  j.attempts = int(s.integer(17));
  j.cancel_requested = s.integer(18) != 0;
  auto outs = nlohmann::json::parse(s.text(19), nullptr, false);
  if (outs.is_array())
    for (const auto& o : outs)
      if (o.is_string()) j.outputs.push_back(o.get<std::string>());
  j.tenant = s.text(21);
  j.result_attempt = int(s.integer(22));
  return j;
}

class SqliteJobStore final : public JobStore {
 public:
  explicit SqliteJobStore(const std::string& path) {
    if (sqlite3_open_v2(path.c_str(), &db_, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_FULLMUTEX,
                        nullptr) != SQLITE_OK) {
      std::string msg = db_ ? sqlite3_errmsg(db_) : "out of memory";
      sqlite3_close(db_);
      throw std::runtime_error("cannot open job database " + path + ": " + msg);
    }
    sqlite3_busy_timeout(db_, 5000);
    exec("PRAGMA journal_mode=WAL");
    // FULL: every commit is fsynced before it returns, so a job answered 202
    // (its row committed) survives a power loss too, not only SIGKILL (NORMAL
    // in WAL mode may lose the last commits). Writes are few (a handful per
    // job, progress at most 5 a second per worker), so an fsync each is affordable.
    exec("PRAGMA synchronous=FULL");
    exec(
        "CREATE TABLE IF NOT EXISTS jobs ("
        " seq INTEGER PRIMARY KEY AUTOINCREMENT,"
        " id TEXT NOT NULL UNIQUE, state TEXT NOT NULL, created_at REAL NOT NULL,"
        " started_at REAL NOT NULL DEFAULT 0, finished_at REAL NOT NULL DEFAULT 0,"
        " stage TEXT NOT NULL DEFAULT '', fraction REAL NOT NULL DEFAULT 0,"
        " stage_seconds TEXT NOT NULL DEFAULT '{}', error_code TEXT, error_status INTEGER,"
        " error_detail TEXT, params TEXT NOT NULL, input_file TEXT NOT NULL,"
        " content_type TEXT NOT NULL, input_bytes INTEGER NOT NULL, idem_key TEXT UNIQUE,"
        " request_hash TEXT NOT NULL, attempts INTEGER NOT NULL DEFAULT 0,"
        " cancel_requested INTEGER NOT NULL DEFAULT 0, outputs TEXT NOT NULL DEFAULT '[]')");
    exec("CREATE INDEX IF NOT EXISTS jobs_state ON jobs(state, seq)");
    // Databases from before tenants: their jobs belong to the tenant-less server.
    if (!has_column("jobs", "tenant")) exec("ALTER TABLE jobs ADD COLUMN tenant TEXT NOT NULL DEFAULT ''");
    exec("CREATE INDEX IF NOT EXISTS jobs_tenant ON jobs(tenant, seq)");
    // Databases from before results were stored per attempt (result_blobs.h):
    // 0, their jobs' results are under the plain names.
    if (!has_column("jobs", "result_attempt"))
      exec("ALTER TABLE jobs ADD COLUMN result_attempt INTEGER NOT NULL DEFAULT 0");
  }
  ~SqliteJobStore() override { sqlite3_close(db_); }

  std::optional<Job> create_or_get_by_key(const Job& job) override {
    std::lock_guard lock(mu_);
    Stmt s(db_,
           "INSERT INTO jobs (id, state, created_at, params, input_file, content_type, input_bytes,"
           " idem_key, request_hash, tenant) VALUES (?,?,?,?,?,?,?,?,?,?)");
    s.bind(1, job.id).bind(2, std::string(to_string(job.state))).bind(3, job.created_at)
        .bind(4, job.params.dump()).bind(5, job.input_file).bind(6, job.content_type)
        .bind(7, job.input_bytes);
    if (job.idempotency_key.empty()) s.bind_null(8); else s.bind(8, stored_key(job.tenant, job.idempotency_key));
    s.bind(9, job.request_hash).bind(10, job.tenant);
    int rc = s.step_rc();
    if (rc == SQLITE_DONE) return get_locked(job.id);
    if (rc == SQLITE_CONSTRAINT && !job.idempotency_key.empty()) {
      Stmt q(db_, (std::string("SELECT ") + kColumns + " FROM jobs WHERE idem_key = ?").c_str());
      q.bind(1, stored_key(job.tenant, job.idempotency_key));
      if (q.step()) return read_job(q);
    }
    throw StorageUnavailable(std::string("sqlite insert: ") + sqlite3_errmsg(db_));
  }

  std::optional<Job> get(const std::string& id) override {
    std::lock_guard lock(mu_);
    return get_locked(id);
  }

  JobPage list(std::optional<JobState> state, int limit, const std::string& cursor,
               const std::optional<std::string>& tenant) override {
    std::lock_guard lock(mu_);
    int64_t before = INT64_MAX;
    if (!cursor.empty()) {
      try { before = std::stoll(cursor); } catch (...) { before = INT64_MAX; }
    }
    std::string sql = std::string("SELECT ") + kColumns + " FROM jobs WHERE seq < ?" +
                      (state ? " AND state = ?" : "") + (tenant ? " AND tenant = ?" : "") +
                      " ORDER BY seq DESC LIMIT ?";
    Stmt s(db_, sql.c_str());
    int i = 1;
    s.bind(i++, before);
    if (state) s.bind(i++, std::string(to_string(*state)));
    if (tenant) s.bind(i++, *tenant);
    s.bind(i++, limit + 1);
    JobPage page;
    int64_t last_seq = 0;
    while (s.step()) {
      if (int(page.jobs.size()) == limit) {
        page.next_cursor = std::to_string(last_seq);
        break;
      }
      page.jobs.push_back(read_job(s));
      last_seq = s.integer(20);
    }
    return page;
  }

  void mark_running(const std::string& id, double at) override {
    std::lock_guard lock(mu_);
    Stmt s(db_,
           "UPDATE jobs SET state='running', started_at=?, stage='', fraction=0, attempts=attempts+1,"
           " stage_seconds='{}' WHERE id=?");
    s.bind(1, at).bind(2, id).step();
  }

  void requeue(const std::string& id) override {
    std::lock_guard lock(mu_);
    Stmt s(db_, "UPDATE jobs SET state='queued', stage='', fraction=0, stage_seconds='{}' WHERE id=?");
    s.bind(1, id).step();
  }

  void update_progress(const std::string& id, const std::string& stage, double fraction,
                       const nlohmann::json& stage_seconds) override {
    std::lock_guard lock(mu_);
    Stmt s(db_, "UPDATE jobs SET stage=?, fraction=?, stage_seconds=? WHERE id=? AND state='running'");
    s.bind(1, stage).bind(2, fraction).bind(3, stage_seconds.dump()).bind(4, id).step();
  }

  void finish(const std::string& id, JobState state, const std::optional<JobError>& error,
              const std::vector<std::string>& outputs, int result_attempt, double at) override {
    std::lock_guard lock(mu_);
    Stmt s(db_,
           "UPDATE jobs SET state=?, finished_at=?, error_code=?, error_status=?, error_detail=?,"
           " outputs=?, result_attempt=?, stage='', fraction=0 WHERE id=?");
    s.bind(1, std::string(to_string(state))).bind(2, at);
    if (error) s.bind(3, error->code).bind(4, error->http_status).bind(5, error->detail);
    else s.bind_null(3).bind_null(4).bind_null(5);
    s.bind(6, nlohmann::json(outputs).dump()).bind(7, result_attempt).bind(8, id).step();
  }

  void request_cancel(const std::string& id) override {
    std::lock_guard lock(mu_);
    Stmt s(db_, "UPDATE jobs SET cancel_requested=1 WHERE id=?");
    s.bind(1, id).step();
  }

  void remove(const std::string& id) override {
    std::lock_guard lock(mu_);
    Stmt s(db_, "DELETE FROM jobs WHERE id=?");
    s.bind(1, id).step();
  }

  std::vector<Job> unfinished() override {
    std::lock_guard lock(mu_);
    Stmt s(db_, (std::string("SELECT ") + kColumns +
                 " FROM jobs WHERE state IN ('queued','running') ORDER BY seq ASC").c_str());
    std::vector<Job> out;
    while (s.step()) out.push_back(read_job(s));
    return out;
  }

  std::vector<std::string> finished_before(double before) override {
    std::lock_guard lock(mu_);
    Stmt s(db_,
           "SELECT id FROM jobs WHERE state IN ('succeeded','failed','canceled') AND finished_at < ?");
    s.bind(1, before);
    std::vector<std::string> out;
    while (s.step()) out.push_back(s.text(0));
    return out;
  }

  std::map<std::string, int64_t> count_by_state() override {
    std::lock_guard lock(mu_);
    std::map<std::string, int64_t> out;
    for (JobState st : {JobState::queued, JobState::running, JobState::succeeded, JobState::failed,
                        JobState::canceled})
      out[to_string(st)] = 0;
    Stmt s(db_, "SELECT state, COUNT(*) FROM jobs GROUP BY state");
    while (s.step()) out[s.text(0)] = s.integer(1);
    return out;
  }

 private:
  void exec(const char* sql) {
    char* err = nullptr;
    if (sqlite3_exec(db_, sql, nullptr, nullptr, &err) != SQLITE_OK) {
      std::string msg = err ? err : "unknown";
      sqlite3_free(err);
      throw std::runtime_error(std::string("sqlite: ") + msg);
    }
  }

  bool has_column(const char* table, const char* column) {
    Stmt s(db_, (std::string("PRAGMA table_info(") + table + ")").c_str());
    while (s.step())
      if (s.text(1) == column) return true;
    return false;
  }

  std::optional<Job> get_locked(const std::string& id) {
    Stmt s(db_, (std::string("SELECT ") + kColumns + " FROM jobs WHERE id = ?").c_str());
    s.bind(1, id);
    if (!s.step()) return std::nullopt;
    return read_job(s);
  }

  sqlite3* db_ = nullptr;
  std::mutex mu_;
};

}  // namespace

std::unique_ptr<JobStore> open_sqlite_job_store(const std::string& path) {
  return std::make_unique<SqliteJobStore>(path);
}

}  // namespace soupuv::server
