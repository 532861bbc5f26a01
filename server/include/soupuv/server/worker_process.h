// One child process running the soupuv CLI under resource limits.
//
// Input: argv, extra environment, limits. The child gets its own process group
// (so a kill reaches anything it starts), RLIMIT_AS / RLIMIT_CPU / no core
// dumps, nice 10, PR_SET_PDEATHSIG so it dies with the server (restart recovery re-runs
// it; an orphan would race the re-run), and every inherited fd closed except
// stdout/stderr. Output: its stderr lines (progress JSON, "soupuv: reason")
// through a callback, and how it ended.
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
};

struct ProcessOutcome {
  bool started = false;
  std::string start_error;
  int exit_code = -1;   // when exited normally
  int signal = 0;       // when killed by a signal
  bool timed_out = false;
  bool canceled = false;  // we sent SIGTERM because `cancel` became true
  double seconds = 0;
  std::string stderr_tail;  // last few KiB, for the job log
};

// Runs to completion. `on_line` gets each stderr line (without newline, capped
// at 64 KiB). `cancel` is polled every 100 ms. `stdout_path`, if set, receives stdout.
// Exception-safe: if `on_line` throws, the worker's process group is killed and
// the worker reaped before the exception leaves run_process.
ProcessOutcome run_process(const std::vector<std::string>& argv, const std::vector<std::string>& extra_env,
                           const ProcessLimits& limits, const std::atomic<bool>& cancel,
                           const std::function<void(const std::string&)>& on_line,
                           const std::string& stdout_path = "");

}  // namespace soupuv::server
