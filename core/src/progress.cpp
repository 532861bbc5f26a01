#include "soupuv/progress.h"

#include <chrono>

#include "soupuv/errors.h"

namespace soupuv {

namespace {
constexpr long long kMinReportIntervalNs = 50'000'000;  // 20 reports/s at most

long long now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}
}  // namespace

void Progress::check_canceled() const {
  if (cancel_->load(std::memory_order_relaxed))
    throw Error(ErrorCode::canceled, "canceled");
}

void Progress::update(std::string_view stage, double fraction) {
  check_canceled();
  if (!callback_) return;
  // Throttle: the first and last report of a stage always go through.
  long long t = now_ns();
  long long last = last_report_ns_.load(std::memory_order_relaxed);
  bool edge = fraction <= 0.0 || fraction >= 1.0;
  if (!edge && t - last < kMinReportIntervalNs) return;
  if (!last_report_ns_.compare_exchange_strong(last, t) && !edge) return;
  callback_(stage, fraction < 0 ? 0 : (fraction > 1 ? 1 : fraction));
}

Progress& Progress::none() {
  static thread_local Progress silent;
  return silent;
}

}  // namespace soupuv
