#pragma once
// Real-time pacing: tick k is due at start + k periods on the monotonic
// clock. Until then the node waits on its socket rather than sleeping, so
// each command is taken in (and its latency read) as it arrives; the command
// newest at the tick acts over the whole following interval (zero-order
// hold). No LCM: the node asks WaitUs() how long to wait.
#include <chrono>
#include <cstdint>

namespace stewart {

class RealTimePacing {
 public:
  using Clock = std::chrono::steady_clock;
  /// The longest single wait, so a stop signal is seen promptly.
  static constexpr int64_t kMaxWaitUs = 50000;

  RealTimePacing(int64_t period_us, Clock::time_point start) : period_(period_us), start_(start) {}

  Clock::time_point Deadline(int64_t tick) const { return start_ + tick * period_; }

  /// At `now`, how long to wait for traffic before `deadline`: 0 once it is
  /// due. Rounds up by a microsecond so the wait never ends just short of it.
  static int64_t WaitUs(Clock::time_point deadline, Clock::time_point now) {
    const Clock::duration left = deadline - now;
    if (left <= Clock::duration::zero()) return 0;
    const int64_t left_us = std::chrono::duration_cast<std::chrono::microseconds>(left).count();
    return left_us + 1 < kMaxWaitUs ? left_us + 1 : kMaxWaitUs;
  }

 private:
  std::chrono::microseconds period_;
  Clock::time_point start_;
};

}  // namespace stewart
