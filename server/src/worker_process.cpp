#include "soupuv/server/worker_process.h"

#include <fcntl.h>
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

extern char** environ;

namespace soupuv::server {
namespace {

using Clock = std::chrono::steady_clock;

double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

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
  struct rlimit none = {0, 0};
  setrlimit(RLIMIT_CORE, &none);
  if (limits.address_space_bytes > 0) {
    struct rlimit as = {rlim_t(limits.address_space_bytes), rlim_t(limits.address_space_bytes)};
    setrlimit(RLIMIT_AS, &as);
  }
  if (limits.cpu_seconds > 0) {
    // Soft limit sends SIGXCPU (reported as "CPU time limit"), hard one SIGKILL.
    struct rlimit cpu = {rlim_t(limits.cpu_seconds), rlim_t(limits.cpu_seconds + 5)};
    setrlimit(RLIMIT_CPU, &cpu);
  }
  int devnull = open("/dev/null", O_RDONLY);
  if (devnull >= 0) dup2(devnull, 0);
  dup2(stdout_fd, 1);
  dup2(stderr_fd, 2);
  // httplib's sockets are not close-on-exec; a worker must not hold the
  // listening port (a restarted server could not bind it).
  syscall(SYS_close_range, 3u, ~0u, 0u);
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
// caller's slot can start another job, and the stderr pipe is closed.
class ChildGuard {
 public:
  ChildGuard(pid_t pid, int pipe_fd) : pid_(pid), pipe_(pipe_fd) {}
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
    close(pipe_);
  }
  int pipe() const { return pipe_; }
  bool reaped() const { return reaped_; }
  // Non-blocking wait; true once the worker has exited (status filled).
  bool try_reap(int& status) {
    if (!reaped_ && waitpid(pid_, &status, WNOHANG) == pid_) reaped_ = true;
    return reaped_;
  }

 private:
  pid_t pid_;
  int pipe_;
  bool reaped_ = false;
};

}  // namespace

ProcessOutcome run_process(const std::vector<std::string>& args, const std::vector<std::string>& extra_env,
                           const ProcessLimits& limits, const std::atomic<bool>& cancel,
                           const std::function<void(const std::string&)>& on_line,
                           const std::string& stdout_path) {
  ProcessOutcome out;
  if (args.empty()) {
    out.start_error = "empty argv";
    return out;
  }
  if (access(args[0].c_str(), X_OK) != 0) {
    out.start_error = "worker binary not executable: " + args[0];
    return out;
  }
  std::vector<std::string> env_store;
  for (char** e = environ; *e; ++e) env_store.emplace_back(*e);
  for (const auto& e : extra_env) env_store.push_back(e);
  std::vector<char*> argv, envp;
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  for (const auto& e : env_store) envp.push_back(const_cast<char*>(e.c_str()));
  envp.push_back(nullptr);

  int pipefd[2];
  if (pipe2(pipefd, O_CLOEXEC) != 0) {
    out.start_error = std::string("pipe: ") + std::strerror(errno);
    return out;
  }
  int stdout_fd = open(stdout_path.empty() ? "/dev/null" : stdout_path.c_str(),
                       O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0640);
  if (stdout_fd < 0) {
    out.start_error = std::string("open stdout: ") + std::strerror(errno);
    close(pipefd[0]);
    close(pipefd[1]);
    return out;
  }
  pid_t parent = getpid();
  auto t0 = Clock::now();
  pid_t pid = fork();
  if (pid < 0) {
    out.start_error = std::string("fork: ") + std::strerror(errno);
    close(pipefd[0]);
    close(pipefd[1]);
    close(stdout_fd);
    return out;
  }
  if (pid == 0) exec_child(argv.data(), envp.data(), limits, pipefd[1], stdout_fd, parent);
  setpgid(pid, pid);  // also from the parent: no race with an early kill
  close(pipefd[1]);
  close(stdout_fd);
  out.started = true;
  ChildGuard child(pid, pipefd[0]);

  std::string partial;
  bool eof = false, term_sent = false, kill_sent = false;
  Clock::time_point term_at{};
  auto signal_group = [&](int sig) { kill(-pid, sig); };
  int status = 0;
  while (!child.reaped()) {
    if (!eof) {
      pollfd p{child.pipe(), POLLIN, 0};
      int rc = poll(&p, 1, 100);
      if (rc > 0) {
        char buf[8192];
        ssize_t n = read(child.pipe(), buf, sizeof buf);
        if (n > 0) {
          out.stderr_tail.append(buf, size_t(n));
          if (out.stderr_tail.size() > 16384) out.stderr_tail.erase(0, out.stderr_tail.size() - 8192);
          partial.append(buf, size_t(n));
          size_t nl;
          while ((nl = partial.find('\n')) != std::string::npos) {
            std::string line = partial.substr(0, nl);
            partial.erase(0, nl + 1);
            on_line(line);  // may throw: `child` then kills and reaps the worker
          }
          if (partial.size() > 65536) {  // a runaway line without newline
            std::string line = partial.substr(0, 65536);
            partial.clear();
            on_line(line);
          }
        } else if (n == 0 || (n < 0 && errno != EINTR && errno != EAGAIN)) {
          eof = true;
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
  // (a surviving grandchild could otherwise hold the pipe open forever).
  kill(-pid, SIGKILL);
  fcntl(child.pipe(), F_SETFL, fcntl(child.pipe(), F_GETFL) | O_NONBLOCK);
  for (;;) {
    char buf[8192];
    ssize_t n = read(child.pipe(), buf, sizeof buf);
    if (n <= 0) break;
    partial.append(buf, size_t(n));
    out.stderr_tail.append(buf, size_t(n));
  }
  size_t nl;
  while ((nl = partial.find('\n')) != std::string::npos) {
    std::string line = partial.substr(0, nl);
    partial.erase(0, nl + 1);
    on_line(line);
  }
  if (!partial.empty()) on_line(partial);
  out.seconds = since(t0);
  if (WIFEXITED(status)) out.exit_code = WEXITSTATUS(status);
  if (WIFSIGNALED(status)) out.signal = WTERMSIG(status);
  if (out.stderr_tail.size() > 8192) out.stderr_tail.erase(0, out.stderr_tail.size() - 8192);
  return out;
}

}  // namespace soupuv::server
