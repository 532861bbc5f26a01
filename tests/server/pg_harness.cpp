#include "pg_harness.h"

#include <arpa/inet.h>
#include <libpq-fe.h>
#include <netinet/in.h>
#include <pwd.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <sstream>

namespace soupuv::test {
namespace fs = std::filesystem;
namespace {

int free_port() {
  int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t len = sizeof a;
  int port = 0;
  if (::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0 &&
      ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len) == 0)
    port = ntohs(a.sin_port);
  ::close(fd);
  return port;
}

std::string quote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

}  // namespace

bool postgres_required() {
  const char* ci = std::getenv("CI");
  return ci && std::string(ci) == "true";
}

std::string TempPostgres::bin_dir() {
  std::error_code ec;
  std::string best;
  for (const auto& e : fs::directory_iterator("/usr/lib/postgresql", ec))
    if (fs::exists(e.path() / "bin" / "initdb") && e.path().string() > best) best = e.path().string();
  return best.empty() ? "" : best + "/bin";
}

bool TempPostgres::run_as_owner(const std::string& command) const {
  const std::string full = user_.empty() ? command : "runuser -u " + user_ + " -- sh -c " + quote(command);
  return std::system((full + " >>" + quote((dir_ / "harness.log").string()) + " 2>&1").c_str()) == 0;
}

TempPostgres::TempPostgres(bool fsync) {
  bin_ = bin_dir();
  if (bin_.empty()) {
    error_ = "PostgreSQL is not installed (no /usr/lib/postgresql/*/bin/initdb)";
    return;
  }
  char templ[] = "/tmp/soupuv-pg-XXXXXX";
  if (!mkdtemp(templ)) {
    error_ = "mkdtemp failed";
    return;
  }
  dir_ = templ;
  if (geteuid() == 0) {
    // PostgreSQL refuses to run as root: the data directory belongs to the
    // package's `postgres` user (or nobody, without the package's user).
    for (const char* u : {"postgres", "nobody"})
      if (passwd* pw = getpwnam(u)) {
        user_ = u;
        if (::chown(dir_.c_str(), pw->pw_uid, pw->pw_gid) != 0) error_ = "chown failed";
        break;
      }
    if (user_.empty()) error_ = "running as root and no unprivileged user to run PostgreSQL as";
  }
  ::chmod(dir_.c_str(), 0700);
  if (!error_.empty()) return;
  port_ = free_port();
  const std::string data = (dir_ / "data").string();
  if (!run_as_owner(bin_ + "/initdb -D " + quote(data) + " -U soupuv --auth=trust --no-sync -E UTF8 --locale=C")) {
    error_ = "initdb failed: " + log();
    return;
  }
  std::ofstream conf(dir_ / "data" / "postgresql.conf", std::ios::app);
  conf << "listen_addresses = '127.0.0.1'\nport = " << port_ << "\nunix_socket_directories = '" << dir_.string()
       << "'\nmax_connections = 200\nfsync = " << (fsync ? "on" : "off") << "\n"
       << (fsync ? "" : "synchronous_commit = off\nfull_page_writes = off\n");
  conf.close();
  start();
}

void TempPostgres::start() {
  if (!run_as_owner(bin_ + "/pg_ctl -D " + quote((dir_ / "data").string()) + " -l " +
                    quote((dir_ / "server.log").string()) + " -w -t 60 start"))
    error_ = "pg_ctl start failed: " + log();
}

void TempPostgres::stop() {
  run_as_owner(bin_ + "/pg_ctl -D " + quote((dir_ / "data").string()) + " -m fast -w -t 60 stop");
}

TempPostgres::~TempPostgres() {
  if (!dir_.empty()) {
    if (!bin_.empty() && fs::exists(dir_ / "data" / "postmaster.pid"))
      run_as_owner(bin_ + "/pg_ctl -D " + quote((dir_ / "data").string()) + " -m immediate -w stop");
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
}

std::string TempPostgres::url(const std::string& database) const {
  return "postgresql://soupuv@127.0.0.1:" + std::to_string(port_) + "/" + database;
}

std::string TempPostgres::fresh_database() {
  const std::string name = "t" + std::to_string(getpid()) + "_" + std::to_string(++databases_);
  PGconn* c = PQconnectdb(url().c_str());
  PGresult* r = PQexec(c, ("CREATE DATABASE " + name).c_str());
  const bool ok = PQresultStatus(r) == PGRES_COMMAND_OK;
  PQclear(r);
  PQfinish(c);
  return ok ? url(name) : "";
}

std::string TempPostgres::log() const {
  std::ostringstream out;
  for (const char* f : {"harness.log", "server.log"}) {
    std::ifstream in(dir_ / f);
    out << in.rdbuf();
  }
  std::string s = out.str();
  return s.size() > 4000 ? s.substr(s.size() - 4000) : s;
}

}  // namespace soupuv::test
