// The worker sandbox: what an untrusted model's parser may touch.
//
// Workers (`soupuv map`, `soupuv inspect`) parse attacker-supplied files. They
// run with Landlock (Linux >= 5.13, unprivileged, works inside containers
// without CAP_SYS_ADMIN where user namespaces are usually blocked): file
// system access is limited to the system's program directories (read and
// execute), the job's input files (read), its scratch directory and the
// shared field cache (read-write), its own /proc/<pid> and /sys; on kernels
// with Landlock ABI >= 4 no TCP bind/connect, >= 6 no signals or abstract
// sockets out of the sandbox. The tokens file, the job database, other jobs'
// files and other processes' /proc entries (the server's environ) are outside
// every rule, whatever the uid (root included).
//
// The ruleset is built in the parent (it may allocate and fail with a
// reason); the child only calls prctl(PR_SET_NO_NEW_PRIVS) and
// landlock_restrict_self, which are async-signal-safe system calls.
#pragma once

#include <sys/types.h>

#include <string>
#include <vector>

#include "soupuv/server/config.h"

namespace soupuv::server {

struct ProcessLimits;

struct SandboxPaths {
  std::vector<std::string> read_files;   // regular files to read (the job's input, texture)
  std::vector<std::string> read_write;   // directories: create, write, remove beneath (scratch, cache)
  std::string program;                   // the worker binary (read + execute)
};

// Highest Landlock ABI of the running kernel; 0 when Landlock is unavailable.
int landlock_abi();

// A Landlock ruleset allowing `paths` plus read/execute of /usr, /lib*, /bin,
// /sbin, /sys, /etc/ld.so.cache, /proc/{cpuinfo,meminfo,stat}, /dev/urandom
// and /dev/null (the child adds its own /proc/<pid>). Returns
// the ruleset fd (O_CLOEXEC; the caller closes it), or -1 with `error` set.
int build_landlock_ruleset(const SandboxPaths& paths, std::string& error);

// The whole environment of a worker: PATH, HOME and TMPDIR (the scratch
// directory), LANG, plus `extra` (NAME=VALUE) and the server's own values of
// the variables named in `pass` (--worker-env). Nothing else of the server's
// environment (secrets passed as variables) reaches a worker.
std::vector<std::string> worker_environment(const std::string& scratch, const std::vector<std::string>& pass,
                                            const std::vector<std::string>& extra);

// Whether workers run under Landlock with this configuration: --worker-sandbox
// auto (the default: when the kernel has it) or landlock (required: the server
// refuses to start without it), not off.
bool sandbox_active(const Config& config);

// Fills the confinement every worker gets: RLIMIT_FSIZE (--worker-max-file-mb),
// RLIMIT_NOFILE 256, RLIMIT_NPROC with room for the uid's tasks and every
// worker's, the scratch directory as cwd, every capability dropped (unless
// --worker-sandbox off), and, when sandbox_active, a
// Landlock ruleset for `paths` (the caller closes limits.landlock_ruleset).
// False with `error` when the sandbox is due but cannot be built: the caller
// must not run the worker (fail closed).
bool confine_worker(const Config& config, const SandboxPaths& paths, const std::string& scratch,
                    ProcessLimits& limits, std::string& error);

// Closes a ruleset fd when it goes out of scope.
struct RulesetCloser {
  int& fd;
  ~RulesetCloser();
};

// Tasks (threads) of every process of real uid `uid` now, for RLIMIT_NPROC
// headroom (the limit counts every task of the uid, the server's included).
int uid_task_count(uid_t uid);

}  // namespace soupuv::server
