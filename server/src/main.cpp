// soupuv-server entry point: parse flags/env, run the App until SIGTERM/SIGINT
// (SIGHUP reloads the tokens file).
#include <signal.h>
#include <unistd.h>

#include <iostream>
#include <thread>

#include "soupuv/server/app.h"
#include "soupuv/server/log.h"

int main(int argc, char** argv) {
  using namespace soupuv::server;
  std::vector<std::string> args(argv + 1, argv + argc);
  for (const auto& a : args)
    if (a == "--help" || a == "-h") {
      std::cout << help_text();
      return 0;
    }
  Config config;
  try {
    config = parse_config(args, process_env());
  } catch (const ConfigError& e) {
    std::cerr << "soupuv-server: " << e.what() << "\n";
    return 2;
  }
  log::init(config.log_level);
  // Signals go to one thread that stops the server; every other thread
  // (HTTP pool, workers) inherits the blocked mask.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGHUP);  // reload --tokens-file
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  signal(SIGPIPE, SIG_IGN);
  try {
    App app(config);
    if (!app.bind()) {
      log::error("cannot bind", {{"host", config.host}, {"port", config.port}});
      return 1;
    }
    std::thread waiter([&] {
      int sig = 0;
      while (sigwait(&signals, &sig) == 0 && sig == SIGHUP) app.reload_tokens();
      log::info("signal received, stopping", {{"signal", sig}});
      app.stop();
    });
    app.serve();
    // serve() returns after stop(); if it returned on its own, wake the waiter.
    kill(getpid(), SIGTERM);
    waiter.join();
    app.stop();
  } catch (const std::exception& e) {
    log::error("startup failed", {{"error", e.what()}});
    return 1;
  }
  return 0;
}
