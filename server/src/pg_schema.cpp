#include "soupuv/server/pg_schema.h"

#include <stdexcept>

namespace soupuv::server {
namespace {

struct Migration {
  int version;
  const char* name;
  const char* sql;
};

// Append only: a released migration is never edited (a database that ran it
// would not run it again), a change is a new one.
const Migration kMigrations[] = {
    {1, "jobs",
     // The columns of SqliteJobStore's table, plus the lease. `params` is the
     // whole validated params JSON as text, byte for byte what the API was
     // given after validation (jsonb would reorder keys): anything a client
     // may add inside params round-trips unchanged, as with SQLite.
     "CREATE TABLE soupuv_jobs ("
     " seq BIGSERIAL PRIMARY KEY,"
     " id TEXT NOT NULL UNIQUE,"
     " state TEXT NOT NULL CHECK (state IN ('queued','running','succeeded','failed','canceled')),"
     " created_at DOUBLE PRECISION NOT NULL,"
     " started_at DOUBLE PRECISION NOT NULL DEFAULT 0,"
     " finished_at DOUBLE PRECISION NOT NULL DEFAULT 0,"
     " stage TEXT NOT NULL DEFAULT '', fraction DOUBLE PRECISION NOT NULL DEFAULT 0,"
     " stage_seconds TEXT NOT NULL DEFAULT '{}',"
     " error_code TEXT, error_status INTEGER, error_detail TEXT,"
     " params TEXT NOT NULL, input_file TEXT NOT NULL, content_type TEXT NOT NULL,"
     " input_bytes BIGINT NOT NULL,"
     " idem_key TEXT UNIQUE,"  // 'tenant\nkey' as in SQLite: unique across the service
     " request_hash TEXT NOT NULL,"
     " attempts INTEGER NOT NULL DEFAULT 0,"
     " cancel_requested BOOLEAN NOT NULL DEFAULT false,"
     " outputs TEXT NOT NULL DEFAULT '[]',"
     " tenant TEXT NOT NULL DEFAULT '',"
     " lease_owner TEXT,"
     " lease_until TIMESTAMPTZ);"
     // The claim's scan (oldest queued), the reaper's (expired leases), the
     // TTL sweep's (oldest finished) and the API's listings.
     "CREATE INDEX soupuv_jobs_queued ON soupuv_jobs (seq) WHERE state = 'queued';"
     "CREATE INDEX soupuv_jobs_leases ON soupuv_jobs (lease_until) WHERE state = 'running';"
     "CREATE INDEX soupuv_jobs_finished ON soupuv_jobs (finished_at)"
     " WHERE state IN ('succeeded','failed','canceled');"
     "CREATE INDEX soupuv_jobs_state ON soupuv_jobs (state, seq);"
     "CREATE INDEX soupuv_jobs_tenant ON soupuv_jobs (tenant, seq);"},
    {2, "blobs",
     // Inputs and results in 1 MiB rows (blob_store.h): streamed in and out a
     // row at a time. EXTERNAL: no pglz compression attempt on bytes that
     // are mostly compressed already (GLB buffers, PNG), still TOASTed.
     "CREATE TABLE soupuv_blobs ("
     " job_id TEXT NOT NULL, name TEXT NOT NULL, bytes BIGINT NOT NULL,"
     " created_at TIMESTAMPTZ NOT NULL DEFAULT now(), PRIMARY KEY (job_id, name));"
     "CREATE TABLE soupuv_blob_chunks ("
     " job_id TEXT NOT NULL, name TEXT NOT NULL, n INTEGER NOT NULL, data BYTEA NOT NULL,"
     " PRIMARY KEY (job_id, name, n));"
     "ALTER TABLE soupuv_blob_chunks ALTER COLUMN data SET STORAGE EXTERNAL;"},
    {3, "result_attempt",
     // Results are blobs per attempt (result_blobs.h); the outcome names the
     // attempt whose blobs they are. 0: a job finished before, whose results
     // are under the plain names.
     "ALTER TABLE soupuv_jobs ADD COLUMN result_attempt INTEGER NOT NULL DEFAULT 0;"},
};

// Any constant shared by every soupuv-server build; 'soupuvdb' in ASCII.
constexpr const char* kMigrationLock = "8315151564140323426";

}  // namespace

int pg_schema_version() { return kMigrations[std::size(kMigrations) - 1].version; }

int migrate_pg_schema(PgConnection& conn) {
  int applied = 0;
  conn.transaction([&](PgConnection& c) {
    c.exec(std::string("SELECT pg_advisory_xact_lock(") + kMigrationLock + ")");
    c.exec(
        "CREATE TABLE IF NOT EXISTS soupuv_schema_migrations ("
        " version INTEGER PRIMARY KEY, name TEXT NOT NULL, applied_at TIMESTAMPTZ NOT NULL DEFAULT now())");
    auto r = c.exec("SELECT COALESCE(MAX(version), 0) FROM soupuv_schema_migrations");
    const int current = int(r.integer(0, 0));
    if (current > pg_schema_version())
      throw std::runtime_error("the database has schema version " + std::to_string(current) +
                               ", newer than this soupuv-server knows (" + std::to_string(pg_schema_version()) +
                               "): run the newer server, or a fresh database");
    for (const auto& m : kMigrations) {
      if (m.version <= current) continue;
      PgResult res(PQexec(c.raw(), m.sql));  // several statements: the simple query protocol
      if (PQresultStatus(res.get()) != PGRES_COMMAND_OK)
        throw std::runtime_error(std::string("migration ") + std::to_string(m.version) + " (" + m.name +
                                 ") failed: " + PQresultErrorMessage(res.get()));
      c.exec("INSERT INTO soupuv_schema_migrations (version, name) VALUES ($1, $2)",
             {pg_int(m.version), PgParam(m.name)});
      ++applied;
    }
  });
  return applied;
}

}  // namespace soupuv::server
