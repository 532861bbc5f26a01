// One child process running the soupuv CLI under resource limits.
//
// Input: argv, environment, limits. The child gets its own process group
// (so a kill reaches anything it starts), RLIMIT_AS / CPU / FSIZE / NOFILE /
// NPROC and no core dumps, nice 10, PR_SET_PDEATHSIG so it dies with the
// server (restart recovery re-runs it; an orphan would race the re-run), the
// Landlock sandbox when given (sandbox.h), and every inherited fd closed
// except stdin (/dev/null), stdout and stderr (both pipes to us). Output: its
// stderr lines (progress JSON, "soupuv: reason") through a callback, its
// stdout up to a cap, and how it ended.
#pragma once

#include <sys/types.h>

#include <atomic>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace soupuv::server {

struct ProcessLimits {
  int64_t address_space_bytes = 0;  // 0: unlimited
  int64_t cpu_seconds = 0;          // 0: unlimited
  double wall_seconds = 0;          // 0: unlimited
  double term_grace_seconds = 5;    // SIGTERM -> SIGKILL delay on cancel/timeout
  int64_t file_size_bytes = 0;      // RLIMIT_FSIZE (SIGXFSZ beyond); 0: unlimited
  int open_files = 0;               // RLIMIT_NOFILE; 0: unchanged
  int processes = 0;                // RLIMIT_NPROC (counts every task of the uid); 0: unchanged
  int64_t stdout_bytes = 1 << 20;   // more stdout than this: the worker is killed (output_exceeded)
  std::string cwd;                  // working directory of the child; empty: unchanged
  // Drop every capability (bounding, ambient, effective, permitted,
  // inheritable) before exec: a worker of a server running as root keeps
  // uid 0 but none of root's powers (no module loading, raw sockets,
  // signalling others, ...). The child fails (exit 125) if root cannot drop them.
  bool drop_capabilities = false;
  // Landlock ruleset fd (sandbox.h) the child restricts itself with; -1: none.
  // Owned by the caller; the child fails (exit 125) rather than run unconfined.
  int landlock_ruleset = -1;
};

// Exit status of a child that could not confine itself or exec the worker.
constexpr int kSandboxFailedExit = 125;

struct ProcessOutcome {
  bool started = false;
  std::string start_error;
  int exit_code = -1;   // when exited normally
  int signal = 0;       // when killed by a signal
  bool timed_out = false;
  bool canceled = false;  // we sent SIGTERM because `cancel` became true
  bool output_exceeded = false;  // killed for writing more than stdout_bytes to stdout
  double seconds = 0;
  std::string stderr_tail;  // last few KiB, for the job log
  std::string stdout_text;  // up to stdout_bytes
};

// Runs to completion. `env` is the child's whole environment (see
// worker_environment in sandbox.h). `on_line` gets each stderr line (without
// newline, capped at 64 KiB). `cancel` is polled every 100 ms.
// Exception-safe: if `on_line` throws, the worker's process group is killed and
// the worker reaped before the exception leaves run_process.
ProcessOutcome run_process(const std::vector<std::string>& argv, const std::vector<std::string>& env,
                           const ProcessLimits& limits, const std::atomic<bool>& cancel,
                           const std::function<void(const std::string&)>& on_line);

}  // namespace soupuv::server
