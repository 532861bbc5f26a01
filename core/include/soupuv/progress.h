// Progress reporting and cancellation for long stages. Every long loop calls
// update(); it forwards to the caller's callback and throws
// Error{canceled} once the cancel token is set, so cancellation needs no other
// plumbing through the algorithms.
#pragma once

#include <atomic>
#include <functional>
#include <memory>
#include <string>
#include <string_view>

namespace soupuv {

class Progress {
 public:
  using Callback = std::function<void(std::string_view stage, double fraction)>;

  Progress() : cancel_(std::make_shared<std::atomic<bool>>(false)) {}
  explicit Progress(Callback cb) : Progress() { callback_ = std::move(cb); }

  // Reports `fraction` in [0,1] of `stage`. Throws Error{canceled} when canceled.
  // Safe to call from several threads; the callback is invoked under a lock-free
  // throttle so hot loops may call it often.
  void update(std::string_view stage, double fraction);

  // Throws Error{canceled} when canceled; for loops that report nothing.
  void check_canceled() const;

  void cancel() { cancel_->store(true); }
  bool canceled() const { return cancel_->load(); }
  std::shared_ptr<std::atomic<bool>> cancel_token() const { return cancel_; }

  // A Progress that reports nothing and is never canceled.
  static Progress& none();

 private:
  Callback callback_;
  std::shared_ptr<std::atomic<bool>> cancel_;
  std::atomic<long long> last_report_ns_{0};
};

}  // namespace soupuv
