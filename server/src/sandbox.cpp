#include "soupuv/server/sandbox.h"

#include "soupuv/server/worker_process.h"

#include <dirent.h>
#include <fcntl.h>
#include <linux/landlock.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstdlib>
#include <cstdio>
#include <cstring>

// Debian 12's kernel headers describe Landlock ABI 2; newer rights are
// defined here with their UAPI values and used only when the kernel reports
// the ABI that has them.
#ifndef LANDLOCK_ACCESS_FS_REFER
#define LANDLOCK_ACCESS_FS_REFER (1ULL << 13)  // ABI 2
#endif
#ifndef LANDLOCK_ACCESS_FS_TRUNCATE
#define LANDLOCK_ACCESS_FS_TRUNCATE (1ULL << 14)  // ABI 3
#endif
#ifndef LANDLOCK_ACCESS_FS_IOCTL_DEV
#define LANDLOCK_ACCESS_FS_IOCTL_DEV (1ULL << 15)  // ABI 5
#endif

namespace soupuv::server {
namespace {

// The ruleset attribute grew with the ABI; the kernel takes the size we pass
// as the version of the structure we know.
struct RulesetAttr {
  uint64_t handled_access_fs;
  uint64_t handled_access_net;  // ABI 4
  uint64_t scoped;              // ABI 6
};
constexpr uint64_t kNetBindTcp = 1ULL << 0, kNetConnectTcp = 1ULL << 1;
constexpr uint64_t kScopeAbstractUnix = 1ULL << 0, kScopeSignal = 1ULL << 1;

uint64_t handled_fs_rights(int abi) {
  uint64_t r = (1ULL << 13) - 1;  // ABI 1: EXECUTE .. MAKE_SYM
  if (abi >= 2) r |= LANDLOCK_ACCESS_FS_REFER;
  if (abi >= 3) r |= LANDLOCK_ACCESS_FS_TRUNCATE;
  if (abi >= 5) r |= LANDLOCK_ACCESS_FS_IOCTL_DEV;
  return r;
}

constexpr uint64_t kReadDir = LANDLOCK_ACCESS_FS_EXECUTE | LANDLOCK_ACCESS_FS_READ_FILE | LANDLOCK_ACCESS_FS_READ_DIR;
constexpr uint64_t kReadFile = LANDLOCK_ACCESS_FS_READ_FILE;
constexpr uint64_t kExecFile = LANDLOCK_ACCESS_FS_EXECUTE | LANDLOCK_ACCESS_FS_READ_FILE;
constexpr uint64_t kWriteDir = kReadDir | LANDLOCK_ACCESS_FS_WRITE_FILE | LANDLOCK_ACCESS_FS_REMOVE_DIR |
                               LANDLOCK_ACCESS_FS_REMOVE_FILE | LANDLOCK_ACCESS_FS_MAKE_DIR |
                               LANDLOCK_ACCESS_FS_MAKE_REG | LANDLOCK_ACCESS_FS_REFER | LANDLOCK_ACCESS_FS_TRUNCATE;
constexpr uint64_t kDevNull = LANDLOCK_ACCESS_FS_READ_FILE | LANDLOCK_ACCESS_FS_WRITE_FILE | LANDLOCK_ACCESS_FS_TRUNCATE;

// Adds "beneath `path`, allow `access`". A path that does not exist is
// skipped (e.g. /lib64 on some systems); any other failure is an error.
bool allow(int ruleset, const std::string& path, uint64_t access, uint64_t handled, std::string& error) {
  int fd = open(path.c_str(), O_PATH | O_CLOEXEC);
  if (fd < 0) {
    if (errno == ENOENT) return true;
    error = "open " + path + ": " + std::strerror(errno);
    return false;
  }
  struct stat st;
  if (fstat(fd, &st) != 0) {
    error = "stat " + path + ": " + std::strerror(errno);
    close(fd);
    return false;
  }
  // Rights that only make sense on directories are refused on files (EINVAL).
  constexpr uint64_t file_rights = LANDLOCK_ACCESS_FS_EXECUTE | LANDLOCK_ACCESS_FS_WRITE_FILE |
                                   LANDLOCK_ACCESS_FS_READ_FILE | LANDLOCK_ACCESS_FS_TRUNCATE |
                                   LANDLOCK_ACCESS_FS_IOCTL_DEV;
  if (!S_ISDIR(st.st_mode)) access &= file_rights;
  landlock_path_beneath_attr rule{};
  rule.allowed_access = access & handled;
  rule.parent_fd = fd;
  long rc = syscall(SYS_landlock_add_rule, ruleset, LANDLOCK_RULE_PATH_BENEATH, &rule, 0);
  int err = errno;
  close(fd);
  if (rc != 0) {
    error = "landlock_add_rule " + path + ": " + std::strerror(err);
    return false;
  }
  return true;
}

}  // namespace

int landlock_abi() {
  static const int abi = [] {
    long v = syscall(SYS_landlock_create_ruleset, nullptr, 0, LANDLOCK_CREATE_RULESET_VERSION);
    return v > 0 ? int(v) : 0;
  }();
  return abi;
}

int build_landlock_ruleset(const SandboxPaths& paths, std::string& error) {
  const int abi = landlock_abi();
  if (abi == 0) {
    error = "the kernel has no Landlock (needs Linux >= 5.13 with landlock in the LSM list)";
    return -1;
  }
  RulesetAttr attr{};
  attr.handled_access_fs = handled_fs_rights(abi);
  size_t size = sizeof attr.handled_access_fs;
  if (abi >= 4) {
    attr.handled_access_net = kNetBindTcp | kNetConnectTcp;  // and no rule allows any port
    size += sizeof attr.handled_access_net;
  }
  if (abi >= 6) {
    attr.scoped = kScopeAbstractUnix | kScopeSignal;
    size += sizeof attr.scoped;
  }
  int ruleset = int(syscall(SYS_landlock_create_ruleset, &attr, size, 0));
  if (ruleset < 0) {
    error = std::string("landlock_create_ruleset: ") + std::strerror(errno);
    return -1;
  }
  const uint64_t h = attr.handled_access_fs;
  bool ok = true;
  // Programs and their libraries (Debian's /bin, /lib are links into /usr),
  // the loader's cache, and what libgomp and glibc read to count CPUs.
  // Not /proc as a whole: other processes' entries (the server's environ)
  // would be readable; the worker's own /proc/<pid> is added by the child.
  for (const char* dir : {"/usr", "/lib", "/lib64", "/bin", "/sbin", "/sys"})
    ok = ok && allow(ruleset, dir, kReadDir, h, error);
  for (const char* file : {"/etc/ld.so.cache", "/etc/localtime", "/dev/urandom", "/proc/cpuinfo", "/proc/meminfo",
                           "/proc/stat"})
    ok = ok && allow(ruleset, file, kReadFile, h, error);
  ok = ok && allow(ruleset, "/dev/null", kDevNull, h, error);
  if (!paths.program.empty()) ok = ok && allow(ruleset, paths.program, kExecFile, h, error);
  for (const auto& f : paths.read_files) ok = ok && allow(ruleset, f, kReadFile, h, error);
  for (const auto& d : paths.read_write) ok = ok && allow(ruleset, d, kWriteDir, h, error);
  if (!ok) {
    close(ruleset);
    return -1;
  }
  return ruleset;
}

std::vector<std::string> worker_environment(const std::string& scratch, const std::vector<std::string>& pass,
                                            const std::vector<std::string>& extra) {
  std::vector<std::string> env = {"PATH=/usr/local/bin:/usr/bin:/bin", "LANG=C.UTF-8", "HOME=" + scratch,
                                  "TMPDIR=" + scratch};
  for (const auto& name : pass)
    if (const char* v = std::getenv(name.c_str())) env.push_back(name + "=" + v);
  env.insert(env.end(), extra.begin(), extra.end());
  return env;
}

bool sandbox_active(const Config& config) { return config.worker_sandbox != "off" && landlock_abi() > 0; }

bool confine_worker(const Config& config, const SandboxPaths& paths, const std::string& scratch,
                    ProcessLimits& limits, std::string& error) {
  limits.file_size_bytes = config.worker_max_file_mb << 20;
  limits.open_files = 256;  // the pipeline needs a few dozen; a parser bug that leaks fds stops here
  // RLIMIT_NPROC counts every task of the real uid on the machine (for a
  // root server without capabilities, every root process): what the uid runs
  // now, every worker's threads and a wide margin for the uid's other
  // processes starting meanwhile; what it stops is a fork bomb.
  limits.processes = uid_task_count(getuid()) + config.workers * (config.threads_per_job() + 16) + 512;
  limits.cwd = scratch;
  limits.drop_capabilities = config.worker_sandbox != "off";
  if (!sandbox_active(config)) return true;
  limits.landlock_ruleset = build_landlock_ruleset(paths, error);
  return limits.landlock_ruleset >= 0;
}

RulesetCloser::~RulesetCloser() {
  if (fd >= 0) close(fd);
  fd = -1;
}

int uid_task_count(uid_t uid) {
  int n = 0;
  DIR* proc = opendir("/proc");
  if (!proc) return 0;
  while (dirent* e = readdir(proc)) {
    if (e->d_name[0] < '0' || e->d_name[0] > '9') continue;
    FILE* f = std::fopen((std::string("/proc/") + e->d_name + "/status").c_str(), "r");
    if (!f) continue;  // gone meanwhile
    char line[256];
    bool mine = false;
    int threads = 0;
    while (std::fgets(line, sizeof line, f)) {
      unsigned real = 0;
      if (std::sscanf(line, "Uid: %u", &real) == 1) mine = real == uid;
      std::sscanf(line, "Threads: %d", &threads);
    }
    std::fclose(f);
    if (mine) n += threads;
  }
  closedir(proc);
  return n;
}

}  // namespace soupuv::server
