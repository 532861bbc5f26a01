// The PostgreSQL schema of soupuv-server, as numbered migrations applied at
// start (pg_schema.cpp). Safe when several nodes start at once: the whole
// run holds a transaction-scoped advisory lock, so one node migrates and the
// others then find the versions recorded and apply nothing.
#pragma once

#include "soupuv/server/pg_connection.h"

namespace soupuv::server {

// Applies the migrations the database lacks; returns how many. Throws
// std::runtime_error if the database has a newer schema than this build
// knows (a downgrade would corrupt it), StorageUnavailable if unreachable.
int migrate_pg_schema(PgConnection& conn);
int pg_schema_version();  // the newest migration this build has

}  // namespace soupuv::server
