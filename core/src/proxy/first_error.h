// FirstError: carries an exception out of an OpenMP parallel region. An
// exception may not leave the region (std::terminate), yet the loops inside
// report progress (which throws Error{canceled}) and check their invariants
// (Error{internal}). run() executes one iteration's body and keeps the first
// exception thrown; later iterations are skipped; rethrow() after the region.
#pragma once

#include <atomic>
#include <exception>
#include <mutex>

namespace soupuv::proxy {

class FirstError {
 public:
  template <class Body>
  void run(Body&& body) {
    if (failed_.load(std::memory_order_relaxed)) return;
    try {
      body();
    } catch (...) {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!error_) error_ = std::current_exception();
      failed_.store(true, std::memory_order_relaxed);
    }
  }
  void rethrow() const {
    if (error_) std::rethrow_exception(error_);
  }

 private:
  std::atomic<bool> failed_{false};
  std::mutex mutex_;
  std::exception_ptr error_;
};

}  // namespace soupuv::proxy
