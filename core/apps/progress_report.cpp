// Progress display and signal-driven cancellation for the CLI (see progress_report.h).
#include "progress_report.h"

#include <atomic>
#include <csignal>
#include <cstdio>
#include <string>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include "cli.h"

namespace soupuv::cli {

namespace {

// The cancel token the signal handler sets. std::atomic<bool> is lock-free on
// every platform we build for, so storing to it is async-signal-safe.
std::atomic<bool>* g_cancel = nullptr;

extern "C" void on_signal(int) {
  if (g_cancel) g_cancel->store(true);
}

bool stderr_is_terminal() { return ::isatty(STDERR_FILENO) == 1; }

void draw_bar(std::string_view stage, double fraction) {
  const int width = 30;
  int filled = static_cast<int>(fraction * width + 0.5);
  std::string bar(filled, '#');
  bar.resize(width, '.');
  std::fprintf(stderr, "\r\033[K[%s] %3d%% %.*s", bar.c_str(), static_cast<int>(fraction * 100 + 0.5),
               static_cast<int>(stage.size()), stage.data());
  std::fflush(stderr);
}

void print_json_line(std::string_view stage, double fraction) {
  // Written by hand to keep the key order the worker protocol fixes.
  std::string name = nlohmann::json(std::string(stage)).dump();
  std::fprintf(stderr, "{\"stage\":%s,\"fraction\":%.4f}\n", name.c_str(), fraction);
  std::fflush(stderr);
}

}  // namespace

ProgressMode parse_progress_mode(const std::string& text) {
  if (text == "bar") return ProgressMode::bar;
  if (text == "json") return ProgressMode::json;
  if (text == "none") return ProgressMode::none;
  throw UsageError{"--progress must be bar, json or none, not '" + text + "'"};
}

Progress make_progress(ProgressMode mode) {
  if (mode == ProgressMode::json) return Progress(print_json_line);
  if (mode == ProgressMode::bar && stderr_is_terminal()) return Progress(draw_bar);
  return Progress();
}

void cancel_on_signals(Progress& progress) {
  static std::shared_ptr<std::atomic<bool>> keep_alive;
  keep_alive = progress.cancel_token();
  g_cancel = keep_alive.get();
  struct sigaction action {};
  action.sa_handler = on_signal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESETHAND;  // the second signal takes the default action
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
}

void finish_progress(ProgressMode mode) {
  if (mode == ProgressMode::bar && stderr_is_terminal()) {
    std::fputs("\r\033[K", stderr);
    std::fflush(stderr);
  }
}

}  // namespace soupuv::cli
