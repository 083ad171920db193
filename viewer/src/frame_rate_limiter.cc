#include "stewart/viewer/frame_rate_limiter.h"

#include <cmath>
#include <string>

#include "stewart/common/check.h"

namespace stewart::viewer {

FrameRateLimiter::FrameRateLimiter(double max_rate_hz) {
  STEWART_CHECK_INPUT(std::isfinite(max_rate_hz) && max_rate_hz > 0.0, "viewer.max_frame_rate_hz",
                      "must be positive, got " + std::to_string(max_rate_hz));
  min_interval_ =
      std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / max_rate_hz));
}

bool FrameRateLimiter::TryTake(Clock::time_point now) {
  if (now < next_allowed_) return false;
  // From now, not from the previous slot: a browser that was slow for a
  // while gets no burst of catch-up frames.
  next_allowed_ = now + min_interval_;
  return true;
}

}  // namespace stewart::viewer
