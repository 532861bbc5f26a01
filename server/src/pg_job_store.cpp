#include "soupuv/server/pg_job_store.h"

#include "soupuv/server/storage.h"

namespace soupuv::server {
namespace {

// The same columns, in the same order, as SqliteJobStore's kColumns.
constexpr const char* kColumns =
    "id, state, created_at, started_at, finished_at, stage, fraction, stage_seconds, error_code, "
    "error_status, error_detail, params, input_file, content_type, input_bytes, idem_key, "
    "request_hash, attempts, cancel_requested, outputs, seq, tenant, result_attempt";

std::string select_jobs() { return std::string("SELECT ") + kColumns + " FROM soupuv_jobs "; }

// The database clock in unix seconds: every time the queue compares or
// records in a worker's path comes from here, never from a node.
constexpr const char* kNow = "EXTRACT(EPOCH FROM now())";

std::string stored_key(const std::string& tenant, const std::string& key) {
  return tenant.empty() ? key : tenant + "\n" + key;
}

Job read_job(const PgResult& r, int row) {
  Job j;
  j.id = r.text(row, 0);
  j.state = parse_job_state(r.text(row, 1)).value_or(JobState::failed);
  j.created_at = r.real(row, 2);
  j.started_at = r.real(row, 3);
  j.finished_at = r.real(row, 4);
  j.stage = r.text(row, 5);
  j.fraction = r.real(row, 6);
  j.stage_seconds = nlohmann::json::parse(r.text(row, 7), nullptr, false);
  if (!j.stage_seconds.is_object()) j.stage_seconds = nlohmann::json::object();
  if (!r.null(row, 8)) j.error = JobError{r.text(row, 8), int(r.integer(row, 9)), r.text(row, 10)};
  j.params = nlohmann::json::parse(r.text(row, 11), nullptr, false);
  if (!j.params.is_object()) j.params = nlohmann::json::object();
  j.input_file = r.text(row, 12);
  j.content_type = r.text(row, 13);
  j.input_bytes = r.integer(row, 14);
  j.idempotency_key = r.text(row, 15);
  if (auto nl = j.idempotency_key.find('\n'); nl != std::string::npos) j.idempotency_key.erase(0, nl + 1);
  j.request_hash = r.text(row, 16);
  j.attempts = int(r.integer(row, 17));
  j.cancel_requested = r.boolean(row, 18);
  auto outs = nlohmann::json::parse(r.text(row, 19), nullptr, false);
  if (outs.is_array())
    for (const auto& o : outs)
      if (o.is_string()) j.outputs.push_back(o.get<std::string>());
  j.tenant = r.text(row, 21);
  j.result_attempt = int(r.integer(row, 22));
  return j;
}

std::vector<Job> read_jobs(const PgResult& r) {
  std::vector<Job> out;
  for (int i = 0; i < r.rows(); ++i) out.push_back(read_job(r, i));
  return out;
}

// A text[] literal; every element quoted and escaped.
std::string array_literal(const std::vector<std::string>& items) {
  std::string out = "{";
  for (size_t i = 0; i < items.size(); ++i) {
    out += i ? ",\"" : "\"";
    for (char c : items[i]) {
      if (c == '"' || c == '\\') out += '\\';
      out += c;
    }
    out += '"';
  }
  return out + "}";
}

std::vector<PgParam> insert_params(const Job& job, JobState state) {
  return {job.id,
          to_string(state),
          job.params.dump(),
          job.input_file,
          job.content_type,
          pg_int(job.input_bytes),
          job.idempotency_key.empty() ? PgParam() : PgParam(stored_key(job.tenant, job.idempotency_key)),
          job.request_hash,
          job.tenant};
}

const std::string kInsert =
    std::string("INSERT INTO soupuv_jobs (id, state, created_at, params, input_file, content_type, input_bytes,"
                " idem_key, request_hash, tenant) VALUES ($1, $2, ") +
    kNow + ", $3, $4, $5, $6, $7, $8, $9) ON CONFLICT (idem_key) DO NOTHING RETURNING " + kColumns;

// The lease of one attempt: the WHERE every worker write carries.
constexpr const char* kOwned = " WHERE id = $1 AND state = 'running' AND lease_owner = $2 AND attempts = $3";

}  // namespace

// ---- JobStore -----------------------------------------------------------------

std::optional<Job> PgJobStore::create_or_get_by_key(const Job& job) {
  auto c = pool_.take();
  std::optional<Job> out;
  c->transaction([&](PgConnection& t) {
    auto r = t.exec(kInsert, insert_params(job, job.state));
    if (r.rows() == 1) {
      out = read_job(r, 0);
      if (job.state == JobState::queued) t.exec("SELECT pg_notify($1, $2)", {kJobsChannel, job.id});
      return;
    }
    auto q = t.exec(select_jobs() + "WHERE idem_key = $1", {stored_key(job.tenant, job.idempotency_key)});
    if (q.rows() == 1) out = read_job(q, 0);
  });
  if (!out) throw StorageUnavailable("postgresql insert: no row inserted and no row with its key");
  return out;
}

std::optional<Job> PgJobStore::get(const std::string& id) {
  auto c = pool_.take();
  auto r = c->exec(select_jobs() + "WHERE id = $1", {id});
  if (r.rows() == 0) return std::nullopt;
  return read_job(r, 0);
}

JobPage PgJobStore::list(std::optional<JobState> state, int limit, const std::string& cursor,
                         const std::optional<std::string>& tenant) {
  int64_t before = INT64_MAX;
  if (!cursor.empty()) {
    try { before = std::stoll(cursor); } catch (...) { before = INT64_MAX; }
  }
  std::vector<PgParam> params = {pg_int(before)};
  std::string sql = select_jobs() + "WHERE seq < $1";
  if (state) {
    params.push_back(to_string(*state));
    sql += " AND state = $" + std::to_string(params.size());
  }
  if (tenant) {
    params.push_back(*tenant);
    sql += " AND tenant = $" + std::to_string(params.size());
  }
  params.push_back(pg_int(limit + 1));
  sql += " ORDER BY seq DESC LIMIT $" + std::to_string(params.size());
  auto c = pool_.take();
  auto r = c->exec(sql, params);
  JobPage page;
  for (int i = 0; i < r.rows(); ++i) {
    if (int(page.jobs.size()) == limit) {
      page.next_cursor = std::to_string(r.integer(i - 1, 20));
      break;
    }
    page.jobs.push_back(read_job(r, i));
  }
  return page;
}

void PgJobStore::mark_running(const std::string& id, double at) {
  auto c = pool_.take();
  c->exec("UPDATE soupuv_jobs SET state = 'running', started_at = $2, stage = '', fraction = 0,"
          " attempts = attempts + 1, stage_seconds = '{}' WHERE id = $1",
          {id, pg_num(at)});
}

void PgJobStore::requeue(const std::string& id) {
  auto c = pool_.take();
  c->transaction([&](PgConnection& t) {
    t.exec("UPDATE soupuv_jobs SET state = 'queued', stage = '', fraction = 0, stage_seconds = '{}',"
           " lease_owner = NULL, lease_until = NULL WHERE id = $1",
           {id});
    t.exec("SELECT pg_notify($1, $2)", {kJobsChannel, id});
  });
}

void PgJobStore::update_progress(const std::string& id, const std::string& stage, double fraction,
                                 const nlohmann::json& stage_seconds) {
  auto c = pool_.take();
  c->exec("UPDATE soupuv_jobs SET stage = $2, fraction = $3, stage_seconds = $4 WHERE id = $1 AND state = 'running'",
          {id, stage, pg_num(fraction), stage_seconds.dump()});
}

void PgJobStore::finish(const std::string& id, JobState state, const std::optional<JobError>& error,
                        const std::vector<std::string>& outputs, int result_attempt, double at) {
  auto c = pool_.take();
  c->exec("UPDATE soupuv_jobs SET state = $2, finished_at = $3, error_code = $4, error_status = $5,"
          " error_detail = $6, outputs = $7, result_attempt = $8, stage = '', fraction = 0, lease_owner = NULL,"
          " lease_until = NULL WHERE id = $1",
          {id, to_string(state), pg_num(at), error ? PgParam(error->code) : PgParam(),
           error ? pg_int(error->http_status) : PgParam(), error ? PgParam(error->detail) : PgParam(),
           nlohmann::json(outputs).dump(), pg_int(result_attempt)});
}

void PgJobStore::request_cancel(const std::string& id) {
  auto c = pool_.take();
  c->exec("UPDATE soupuv_jobs SET cancel_requested = true WHERE id = $1", {id});
}

void PgJobStore::remove(const std::string& id) {
  auto c = pool_.take();
  c->transaction([&](PgConnection& t) {
    t.exec("DELETE FROM soupuv_jobs WHERE id = $1", {id});
    t.exec("DELETE FROM soupuv_blob_chunks WHERE job_id = $1", {id});
    t.exec("DELETE FROM soupuv_blobs WHERE job_id = $1", {id});
  });
}

std::vector<Job> PgJobStore::unfinished() {
  auto c = pool_.take();
  return read_jobs(c->exec(select_jobs() + "WHERE state IN ('queued', 'running') ORDER BY seq ASC"));
}

std::vector<std::string> PgJobStore::finished_before(double before) {
  auto c = pool_.take();
  auto r = c->exec("SELECT id FROM soupuv_jobs WHERE state IN ('succeeded', 'failed', 'canceled') AND finished_at < $1",
                   {pg_num(before)});
  std::vector<std::string> out;
  for (int i = 0; i < r.rows(); ++i) out.push_back(r.text(i, 0));
  return out;
}

std::map<std::string, int64_t> PgJobStore::count_by_state() {
  std::map<std::string, int64_t> out;
  for (JobState st : {JobState::queued, JobState::running, JobState::succeeded, JobState::failed,
                      JobState::canceled})
    out[to_string(st)] = 0;
  auto c = pool_.take();
  auto r = c->exec("SELECT state, COUNT(*) FROM soupuv_jobs GROUP BY state");
  for (int i = 0; i < r.rows(); ++i) out[r.text(i, 0)] = r.integer(i, 1);
  return out;
}

// ---- JobQueue -------------------------------------------------------------------

SubmitAnswer PgJobStore::submit(const Job& job, int capacity) {
  SubmitAnswer out;
  auto c = pool_.take();
  c->transaction([&](PgConnection& t) {
    // Capacity is counted across the service: submissions take one
    // transaction-scoped advisory lock, so two nodes cannot both see 49 of
    // 50 and both insert. Held for a count on a partial index and one
    // insert: far below an upload's own cost.
    t.exec("SELECT pg_advisory_xact_lock(8315151564140323427)");
    if (!job.idempotency_key.empty()) {
      auto q = t.exec(select_jobs() + "WHERE idem_key = $1", {stored_key(job.tenant, job.idempotency_key)});
      if (q.rows() == 1) {
        out = {Admission::duplicate, read_job(q, 0)};
        return;
      }
    }
    auto n = t.exec("SELECT COUNT(*) FROM soupuv_jobs WHERE state = 'queued'");
    if (n.integer(0, 0) >= capacity) {
      out = {Admission::full, std::nullopt};
      return;
    }
    auto r = t.exec(kInsert, insert_params(job, JobState::queued));
    if (r.rows() != 1) throw StorageUnavailable("postgresql insert: the job was not inserted");
    out = {Admission::accepted, read_job(r, 0)};
    t.exec("SELECT pg_notify($1, $2)", {kJobsChannel, job.id});  // delivered at commit
  });
  return out;
}

std::optional<std::pair<Job, Lease>> PgJobStore::claim(const std::string& owner, double lease_seconds) {
  auto c = pool_.take();
  // SKIP LOCKED: claimers racing for the head of the queue each take a
  // different row instead of queueing behind one another's lock.
  auto r = c->exec(std::string("UPDATE soupuv_jobs SET state = 'running', lease_owner = $1,"
                               " lease_until = now() + make_interval(secs => $2), started_at = ") +
                       kNow + ", attempts = attempts + 1, stage = '', fraction = 0, stage_seconds = '{}'"
                              " WHERE seq = (SELECT seq FROM soupuv_jobs WHERE state = 'queued'"
                              " ORDER BY seq LIMIT 1 FOR UPDATE SKIP LOCKED) RETURNING " + kColumns,
                   {owner, pg_num(lease_seconds)});
  if (r.rows() == 0) return std::nullopt;
  Job j = read_job(r, 0);
  Lease l{j.id, owner, j.attempts};
  return std::make_pair(std::move(j), std::move(l));
}

std::vector<HeartbeatAnswer> PgJobStore::heartbeat(const std::vector<Lease>& leases, double lease_seconds) {
  std::vector<HeartbeatAnswer> out;
  if (leases.empty()) return out;
  std::vector<std::string> ids, owners, attempts;
  for (const auto& l : leases) {
    ids.push_back(l.id);
    owners.push_back(l.owner);
    attempts.push_back(std::to_string(l.attempt));
  }
  auto c = advisory_.take();
  auto r = c->exec(
      "UPDATE soupuv_jobs j SET lease_until = now() + make_interval(secs => $4)"
      " FROM unnest($1::text[], $2::text[], $3::int[]) AS l(id, owner, attempt)"
      " WHERE j.id = l.id AND j.state = 'running' AND j.lease_owner = l.owner AND j.attempts = l.attempt"
      " RETURNING j.id, j.cancel_requested",
      {array_literal(ids), array_literal(owners), array_literal(attempts), pg_num(lease_seconds)});
  std::map<std::string, bool> held;
  for (int i = 0; i < r.rows(); ++i) held[r.text(i, 0)] = r.boolean(i, 1);
  for (const auto& l : leases) {
    auto it = held.find(l.id);
    out.push_back({l.id, it != held.end(), it != held.end() && it->second});
  }
  return out;
}

bool PgJobStore::progress(const Lease& lease, const std::string& stage, double fraction,
                          const nlohmann::json& stage_seconds) {
  auto c = advisory_.take();
  return c->exec(std::string("UPDATE soupuv_jobs SET stage = $4, fraction = $5, stage_seconds = $6") + kOwned,
                 {lease.id, lease.owner, pg_int(lease.attempt), stage, pg_num(fraction), stage_seconds.dump()})
             .affected() == 1;
}

bool PgJobStore::complete(const Lease& lease, JobState state, const std::optional<JobError>& error,
                          const std::vector<std::string>& outputs) {
  auto c = pool_.take();
  // The one statement that makes this attempt's blobs (result_blobs.h) the
  // job's result: result_attempt is the lease's attempt, set with the state
  // and only while the lease is held, so a late loser's blobs never become it.
  return c->exec(std::string("UPDATE soupuv_jobs SET state = $4, finished_at = ") + kNow +
                     ", error_code = $5, error_status = $6, error_detail = $7, outputs = $8, result_attempt = $3,"
                     " stage = '', fraction = 0, lease_owner = NULL, lease_until = NULL" + kOwned,
                 {lease.id, lease.owner, pg_int(lease.attempt), to_string(state),
                  error ? PgParam(error->code) : PgParam(), error ? pg_int(error->http_status) : PgParam(),
                  error ? PgParam(error->detail) : PgParam(), nlohmann::json(outputs).dump()})
             .affected() == 1;
}

bool PgJobStore::release(const Lease& lease) {
  auto c = pool_.take();
  bool done = false;
  c->transaction([&](PgConnection& t) {
    done = t.exec(std::string("UPDATE soupuv_jobs SET state = 'queued', stage = '', fraction = 0,"
                              " stage_seconds = '{}', lease_owner = NULL, lease_until = NULL") + kOwned,
                  {lease.id, lease.owner, pg_int(lease.attempt)})
               .affected() == 1;
    if (done) t.exec("SELECT pg_notify($1, $2)", {kJobsChannel, lease.id});
  });
  return done;
}

ReapResult PgJobStore::reap(int max_attempts) {
  ReapResult out;
  auto c = pool_.take();
  c->transaction([&](PgConnection& t) {
    // Row locks make this safe on every node at once: a row another reaper
    // (or its owner's late write) holds is skipped now and seen next round.
    auto r = t.exec(
        std::string("UPDATE soupuv_jobs SET"
                    " state = CASE WHEN cancel_requested THEN 'canceled' WHEN attempts < $1 THEN 'queued'"
                    " ELSE 'failed' END,"
                    " finished_at = CASE WHEN cancel_requested OR attempts >= $1 THEN ") +
            kNow + " ELSE 0 END,"
                   " error_code = CASE WHEN NOT cancel_requested AND attempts >= $1 THEN 'lost' END,"
                   " error_status = CASE WHEN NOT cancel_requested AND attempts >= $1 THEN 500 END,"
                   " error_detail = CASE WHEN NOT cancel_requested AND attempts >= $1 THEN"
                   " 'the node running the job stopped renewing its lease on each of its ' || attempts ||"
                   " ' attempts (killed, stopped or cut off from the database)' END,"
                   " stage = '', fraction = 0, stage_seconds = CASE WHEN attempts < $1 THEN '{}' ELSE stage_seconds END,"
                   " lease_owner = NULL, lease_until = NULL"
                   " WHERE seq IN (SELECT seq FROM soupuv_jobs WHERE state = 'running' AND lease_until < now()"
                   " FOR UPDATE SKIP LOCKED) RETURNING id, state",
        {pg_int(max_attempts)});
    for (int i = 0; i < r.rows(); ++i)
      (r.text(i, 1) == "queued" ? out.requeued : out.failed).push_back(r.text(i, 0));
    if (!out.requeued.empty()) t.exec("SELECT pg_notify($1, '')", {kJobsChannel});
  });
  return out;
}

bool PgJobStore::cancel_queued(const std::string& id) {
  auto c = pool_.take();
  return c->exec(std::string("UPDATE soupuv_jobs SET state = 'canceled', cancel_requested = true, finished_at = ") +
                     kNow + " WHERE id = $1 AND state = 'queued'",
                 {id})
             .affected() == 1;
}

void PgJobStore::notify_cancel(const std::string& id) {
  auto c = pool_.take();
  c->exec("SELECT pg_notify($1, $2)", {kCancelChannel, id});
}

std::vector<std::string> PgJobStore::expire(double ttl_seconds) {
  std::vector<std::string> ids;
  auto c = pool_.take();
  c->transaction([&](PgConnection& t) {
    // At most 500 a round, so one transaction stays short; the sweeper comes back.
    auto r = t.exec(std::string("DELETE FROM soupuv_jobs WHERE seq IN (SELECT seq FROM soupuv_jobs"
                                " WHERE state IN ('succeeded', 'failed', 'canceled') AND finished_at < ") +
                        kNow + " - $1 ORDER BY finished_at LIMIT 500 FOR UPDATE SKIP LOCKED) RETURNING id",
                    {pg_num(ttl_seconds)});
    for (int i = 0; i < r.rows(); ++i) ids.push_back(r.text(i, 0));
    if (!ids.empty()) {
      const std::string arr = array_literal(ids);
      t.exec("DELETE FROM soupuv_blob_chunks WHERE job_id = ANY($1::text[])", {arr});
      t.exec("DELETE FROM soupuv_blobs WHERE job_id = ANY($1::text[])", {arr});
    }
    // Blobs of uploads that never became a job (the node died between
    // storing the input and inserting the row), after an hour.
    t.exec("DELETE FROM soupuv_blob_chunks c USING soupuv_blobs b WHERE c.job_id = b.job_id AND c.name = b.name"
           " AND b.created_at < now() - interval '1 hour'"
           " AND NOT EXISTS (SELECT 1 FROM soupuv_jobs j WHERE j.id = b.job_id)");
    t.exec("DELETE FROM soupuv_blobs b WHERE b.created_at < now() - interval '1 hour'"
           " AND NOT EXISTS (SELECT 1 FROM soupuv_jobs j WHERE j.id = b.job_id)");
  });
  return ids;
}

int64_t PgJobStore::queued() {
  auto c = pool_.take();
  return c->exec("SELECT COUNT(*) FROM soupuv_jobs WHERE state = 'queued'").integer(0, 0);
}

}  // namespace soupuv::server
