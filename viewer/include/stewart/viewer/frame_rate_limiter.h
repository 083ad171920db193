#pragma once
// At most one frame per 1 / max_rate_hz to one browser. A frame that comes
// sooner is not queued: the sender skips it and sends whatever is newest
// once the interval has passed, so a slow browser costs frames, never memory.
#include <chrono>

namespace stewart::viewer {

class FrameRateLimiter {
 public:
  using Clock = std::chrono::steady_clock;
  /// Throws InputError unless max_rate_hz is positive and finite.
  explicit FrameRateLimiter(double max_rate_hz);
  /// When the next frame may go (now, if that has passed).
  Clock::time_point NextAllowed() const { return next_allowed_; }
  /// Whether a frame may go at `now`; if so, counts it as sent.
  bool TryTake(Clock::time_point now);

 private:
  Clock::duration min_interval_;
  Clock::time_point next_allowed_{};
};

}  // namespace stewart::viewer
