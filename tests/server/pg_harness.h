// A real PostgreSQL server for tests: initdb + pg_ctl in a temporary
// directory, on a free loopback port, as an unprivileged user when the tests
// run as root (CI does; PostgreSQL refuses to run as root). Debian's
// postgresql package (scripts/install-deps.sh) provides the binaries under
// /usr/lib/postgresql/<version>/bin.
#pragma once

#include <filesystem>
#include <string>

namespace soupuv::test {

class TempPostgres {
 public:
  // `fsync`: off for the contract and cluster tests (they test behaviour,
  // not power loss, and share the disk with other builds); on for benchmarks.
  explicit TempPostgres(bool fsync = false);
  ~TempPostgres();  // stops the server (immediate) and removes its directory
  TempPostgres(const TempPostgres&) = delete;

  // Empty when the server could not be started; error() says why.
  bool ok() const { return error_.empty(); }
  const std::string& error() const { return error_; }
  int port() const { return port_; }
  std::string url(const std::string& database = "postgres") const;
  // A new empty database on this server; its URL.
  std::string fresh_database();
  void stop();     // pg_ctl stop -m fast
  void start();
  std::string log() const;  // the server's log file

  static std::string bin_dir();  // "" when PostgreSQL is not installed

 private:
  bool run_as_owner(const std::string& command) const;
  std::filesystem::path dir_;
  std::string user_;  // runuser target when root; empty otherwise
  std::string bin_;
  int port_ = 0;
  int databases_ = 0;
  std::string error_;
};

// True when tests must not skip for a missing PostgreSQL (CI=true).
bool postgres_required();

}  // namespace soupuv::test
