#include "soupuv/server/worker_process.h"

#include <fcntl.h>
#include <linux/capability.h>
#include <linux/landlock.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <utility>

namespace soupuv::server {
namespace {

using Clock = std::chrono::steady_clock;

double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

void set_limit(int resource, int64_t value) {
  struct rlimit r = {rlim_t(value), rlim_t(value)};
  setrlimit(resource, &r);
}

[[noreturn]] void die(const char* msg) {
  ssize_t ignored = write(2, msg, strlen(msg));
  (void)ignored;
  _exit(kSandboxFailedExit);
}

// Every fd from 3 up goes: httplib's sockets are not close-on-exec, and a
// worker must neither hold the listening port (a restarted server could not
// bind it) nor read the job database through an inherited descriptor.
// close_range needs Linux 5.9 and may be refused by a seccomp profile; then
// each descriptor below the limit is closed one by one.
void close_inherited_fds() {
  if (syscall(SYS_close_range, 3u, ~0u, 0u) == 0) return;
  struct rlimit r;
  rlim_t top = getrlimit(RLIMIT_NOFILE, &r) == 0 ? r.rlim_cur : 1024;
  if (top == RLIM_INFINITY || top > (1u << 20)) top = 1u << 20;
  for (rlim_t fd = 3; fd < top; ++fd) close(int(fd));
}

// Empties the bounding set first (an exec by uid 0 would otherwise be given
// every capability again), then the ambient set, then this process's own
// sets. Raw system calls only (async-signal-safe). False if any step failed
// (expected for a non-root caller, which has nothing to drop).
bool drop_all_capabilities() {
  bool ok = true;
  for (int cap = 0; cap < 64; ++cap)
    if (prctl(PR_CAPBSET_DROP, cap, 0, 0, 0) != 0 && errno != EINVAL) ok = false;
  if (prctl(PR_CAP_AMBIENT, PR_CAP_AMBIENT_CLEAR_ALL, 0, 0, 0) != 0) ok = false;
  __user_cap_header_struct header{_LINUX_CAPABILITY_VERSION_3, 0};
  __user_cap_data_struct data[2] = {};
  if (syscall(SYS_capset, &header, data) != 0) ok = false;
  return ok;
}

// Only async-signal-safe calls between fork and exec: everything is prepared
// before the fork.
[[noreturn]] void exec_child(char* const* argv, char* const* envp, const ProcessLimits& limits,
                             int stderr_fd, int stdout_fd, pid_t parent) {
  setpgid(0, 0);
  prctl(PR_SET_PDEATHSIG, SIGKILL);
  if (getppid() != parent) _exit(127);  // parent died before prctl took effect
  // Below the server's own priority: status polls and uploads stay quick while
  // every worker is computing.
  setpriority(PRIO_PROCESS, 0, 10);
  set_limit(RLIMIT_CORE, 0);
  if (limits.address_space_bytes > 0) set_limit(RLIMIT_AS, limits.address_space_bytes);
  if (limits.cpu_seconds > 0) {
    // Soft limit sends SIGXCPU (reported as "CPU time limit"), hard one SIGKILL.
    struct rlimit cpu = {rlim_t(limits.cpu_seconds), rlim_t(limits.cpu_seconds + 5)};
    setrlimit(RLIMIT_CPU, &cpu);
  }
  if (limits.file_size_bytes > 0) set_limit(RLIMIT_FSIZE, limits.file_size_bytes);
  if (limits.processes > 0) set_limit(RLIMIT_NPROC, limits.processes);
  int devnull = open("/dev/null", O_RDONLY);
  if (devnull >= 0) dup2(devnull, 0);
  dup2(stdout_fd, 1);
  dup2(stderr_fd, 2);
  if (!limits.cwd.empty() && chdir(limits.cwd.c_str()) != 0) die("soupuv: cannot enter the worker's scratch directory\n");
  if (limits.landlock_ruleset >= 0) {
    // The worker's own /proc/<pid> (what glibc, libgomp and sanitizers read),
    // added here because only the child knows its pid. All of /proc is not
    // granted: /proc/<server>/environ stays readable to a Landlock-confined
    // process on current kernels (checked by the sandbox test).
    int self = open("/proc/self", O_PATH | O_CLOEXEC);
    if (self >= 0) {
      landlock_path_beneath_attr rule{};
      rule.allowed_access = LANDLOCK_ACCESS_FS_READ_FILE | LANDLOCK_ACCESS_FS_READ_DIR;
      rule.parent_fd = self;
      syscall(SYS_landlock_add_rule, limits.landlock_ruleset, LANDLOCK_RULE_PATH_BENEATH, &rule, 0);
      close(self);
    }
    // No setuid binary may regain what the sandbox takes (and Landlock
    // requires it of an unprivileged caller).
    if (prctl(PR_SET_NO_NEW_PRIVS, 1, 0, 0, 0) != 0) die("soupuv: worker sandbox: no_new_privs refused\n");
    if (syscall(SYS_landlock_restrict_self, limits.landlock_ruleset, 0) != 0)
      die("soupuv: worker sandbox could not be applied\n");
  }
  if (limits.drop_capabilities && !drop_all_capabilities() && geteuid() == 0)
    die("soupuv: worker sandbox: capabilities could not be dropped\n");
  close_inherited_fds();  // the ruleset fd too
  if (limits.open_files > 0) set_limit(RLIMIT_NOFILE, limits.open_files);
  sigset_t empty;
  sigemptyset(&empty);
  sigprocmask(SIG_SETMASK, &empty, nullptr);
  execve(argv[0], argv, envp);
  const char msg[] = "soupuv: cannot execute worker binary\n";
  ssize_t ignored = write(2, msg, sizeof msg - 1);
  (void)ignored;
  _exit(127);
}

// Owns a started worker until it is reaped. Whatever way run_process is left
// (normal end, or an exception from the line callback or the allocator), the
// worker's whole process group is killed and the worker reaped before the
// caller's slot can start another job, and the pipes are closed.
class ChildGuard {
 public:
  ChildGuard(pid_t pid, int err_fd, int out_fd) : pid_(pid), err_(err_fd), out_(out_fd) {}
  ChildGuard(const ChildGuard&) = delete;
  ChildGuard& operator=(const ChildGuard&) = delete;
  ~ChildGuard() {
    if (!reaped_) {
      kill(-pid_, SIGKILL);
      kill(pid_, SIGKILL);  // in case setpgid lost a race and it has no group yet
      int status;
      while (waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
      }
    }
    close(err_);
    close(out_);
  }
  int err() const { return err_; }
  int out() const { return out_; }
  bool reaped() const { return reaped_; }
  // Non-blocking wait; true once the worker has exited (status filled).
  bool try_reap(int& status) {
    if (!reaped_ && waitpid(pid_, &status, WNOHANG) == pid_) reaped_ = true;
    return reaped_;
  }

 private:
  pid_t pid_;
  int err_, out_;
  bool reaped_ = false;
};

// Splits stderr into lines for the callback and keeps a bounded tail for the job log.
class StderrLines {
 public:
  explicit StderrLines(const std::function<void(const std::string&)>& on_line) : on_line_(on_line) {}
  void add(const char* data, size_t n, std::string& tail) {
    tail.append(data, n);
    if (tail.size() > 16384) tail.erase(0, tail.size() - 8192);
    partial_.append(data, n);
    size_t nl;
    while ((nl = partial_.find('\n')) != std::string::npos) {
      std::string line = partial_.substr(0, nl);
      partial_.erase(0, nl + 1);
      on_line_(line);  // may throw: ChildGuard then kills and reaps the worker
    }
    if (partial_.size() > 65536) {  // a runaway line without newline
      std::string line = partial_.substr(0, 65536);
      partial_.clear();
      on_line_(line);
    }
  }
  void flush() {
    if (!partial_.empty()) on_line_(std::exchange(partial_, std::string()));
  }

 private:
  const std::function<void(const std::string&)>& on_line_;
  std::string partial_;
};

}  // namespace

ProcessOutcome run_process(const std::vector<std::string>& args, const std::vector<std::string>& env,
                           const ProcessLimits& limits, const std::atomic<bool>& cancel,
                           const std::function<void(const std::string&)>& on_line) {
  ProcessOutcome out;
  if (args.empty()) {
    out.start_error = "empty argv";
    return out;
  }
  if (access(args[0].c_str(), X_OK) != 0) {
    out.start_error = "worker binary not executable: " + args[0];
    return out;
  }
  std::vector<char*> argv, envp;
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  for (const auto& e : env) envp.push_back(const_cast<char*>(e.c_str()));
  envp.push_back(nullptr);

  int errp[2], outp[2];
  if (pipe2(errp, O_CLOEXEC) != 0) {
    out.start_error = std::string("pipe: ") + std::strerror(errno);
    return out;
  }
  if (pipe2(outp, O_CLOEXEC) != 0) {
    out.start_error = std::string("pipe: ") + std::strerror(errno);
    close(errp[0]);
    close(errp[1]);
    return out;
  }
  pid_t parent = getpid();
  auto t0 = Clock::now();
  pid_t pid = fork();
  if (pid < 0) {
    out.start_error = std::string("fork: ") + std::strerror(errno);
    for (int fd : {errp[0], errp[1], outp[0], outp[1]}) close(fd);
    return out;
  }
  if (pid == 0) exec_child(argv.data(), envp.data(), limits, errp[1], outp[1], parent);
  setpgid(pid, pid);  // also from the parent: no race with an early kill
  close(errp[1]);
  close(outp[1]);
  out.started = true;
  ChildGuard child(pid, errp[0], outp[0]);
  StderrLines lines(on_line);

  bool err_open = true, out_open = true, term_sent = false, kill_sent = false;
  Clock::time_point term_at{};
  auto signal_group = [&](int sig) { kill(-pid, sig); };
  int status = 0;
  while (!child.reaped()) {
    if (err_open || out_open) {
      pollfd p[2] = {{err_open ? child.err() : -1, POLLIN, 0}, {out_open ? child.out() : -1, POLLIN, 0}};
      if (poll(p, 2, 100) > 0) {
        char buf[8192];
        if (p[0].revents) {
          ssize_t n = read(child.err(), buf, sizeof buf);
          if (n > 0) lines.add(buf, size_t(n), out.stderr_tail);
          else if (n == 0 || (errno != EINTR && errno != EAGAIN)) err_open = false;
        }
        if (p[1].revents) {
          ssize_t n = read(child.out(), buf, sizeof buf);
          if (n > 0) {
            // stdout is for nothing the server uses beyond a help text: a
            // flood is a misbehaving worker, stopped at the cap.
            const size_t room = size_t(std::max<int64_t>(0, limits.stdout_bytes - int64_t(out.stdout_text.size())));
            out.stdout_text.append(buf, std::min(room, size_t(n)));
            if (size_t(n) > room && !out.output_exceeded) {
              out.output_exceeded = true;
              signal_group(SIGKILL);
              kill_sent = term_sent = true;
            }
          } else if (n == 0 || (errno != EINTR && errno != EAGAIN)) {
            out_open = false;
          }
        }
      }
    } else {
      usleep(20000);
    }
    if (child.try_reap(status)) break;
    if (!term_sent) {
      if (cancel.load()) {
        out.canceled = true;
      } else if (limits.wall_seconds > 0 && since(t0) > limits.wall_seconds) {
        out.timed_out = true;
      }
      if (out.canceled || out.timed_out) {
        signal_group(SIGTERM);  // the CLI turns it into the pipeline's cancel flag
        term_sent = true;
        term_at = Clock::now();
      }
    } else if (!kill_sent && since(term_at) > limits.term_grace_seconds) {
      signal_group(SIGKILL);
      kill_sent = true;
    }
  }
  // Anything the worker left behind in its group goes too, before draining
  // (a surviving grandchild could otherwise hold a pipe open forever).
  kill(-pid, SIGKILL);
  fcntl(child.err(), F_SETFL, fcntl(child.err(), F_GETFL) | O_NONBLOCK);
  for (;;) {
    char buf[8192];
    ssize_t n = read(child.err(), buf, sizeof buf);
    if (n <= 0) break;
    lines.add(buf, size_t(n), out.stderr_tail);
  }
  lines.flush();
  // stdout too: a worker that printed more than one read's worth and exited
  // at once (`soupuv capabilities --json`) left the rest in the pipe.
  fcntl(child.out(), F_SETFL, fcntl(child.out(), F_GETFL) | O_NONBLOCK);
  while (!out.output_exceeded) {
    char buf[8192];
    ssize_t n = read(child.out(), buf, sizeof buf);
    if (n <= 0) break;
    const size_t room = size_t(std::max<int64_t>(0, limits.stdout_bytes - int64_t(out.stdout_text.size())));
    out.stdout_text.append(buf, std::min(room, size_t(n)));
    out.output_exceeded = size_t(n) > room;
  }
  out.seconds = since(t0);
  if (WIFEXITED(status)) out.exit_code = WEXITSTATUS(status);
  if (WIFSIGNALED(status)) out.signal = WTERMSIG(status);
  if (out.stderr_tail.size() > 8192) out.stderr_tail.erase(0, out.stderr_tail.size() - 8192);
  return out;
}

}  // namespace soupuv::server
