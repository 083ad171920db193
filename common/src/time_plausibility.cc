#include "stewart/common/time_plausibility.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "stewart/common/check.h"

namespace stewart {
namespace {

/// a - b without overflow: utimes come from the bus and can be anything.
int64_t SaturatingDifference(int64_t a, int64_t b) {
  int64_t d = 0;
  if (!__builtin_sub_overflow(a, b, &d)) return d;
  return a > b ? std::numeric_limits<int64_t>::max() : std::numeric_limits<int64_t>::min();
}

}  // namespace

const char* ToString(TimeVerdict verdict) {
  switch (verdict) {
    case TimeVerdict::kPlausible:
      return "plausible";
    case TimeVerdict::kBehindWindow:
      return "behind_window";
    case TimeVerdict::kAheadOfWindow:
      return "ahead_of_window";
    case TimeVerdict::kAheadOfWallClock:
      return "ahead_of_wall_clock";
  }
  return "unknown";
}

TimePlausibility::TimePlausibility(const TimePlausibilityParams& params)
    : window_us_(std::llround(params.window_s * 1e6)), max_rate_(params.max_rate) {
  STEWART_CHECK(params.window_s > 0.0 && std::isfinite(params.window_s),
                "the time window must be positive");
  STEWART_CHECK(params.max_rate >= 1.0 && std::isfinite(params.max_rate),
                "stack time runs at least at the wall rate");
}

TimeVerdict TimePlausibility::Check(int64_t utime, std::optional<int64_t> receive_wall_us) const {
  // Stack time is never ahead of the wall clock of the host it runs on.
  const bool ahead_of_wall =
      receive_wall_us && SaturatingDifference(utime, *receive_wall_us) > window_us_;
  if (!anchored_) return ahead_of_wall ? TimeVerdict::kAheadOfWallClock : TimeVerdict::kPlausible;
  const int64_t ahead_us = SaturatingDifference(utime, newest_utime_);
  if (ahead_us < -window_us_) return TimeVerdict::kBehindWindow;
  if (ahead_us <= window_us_) return TimeVerdict::kPlausible;
  // Further ahead: only as far as stack time can have run since the newest
  // accepted message, on the wall clock of the receive path.
  if (!receive_wall_us || !newest_receive_wall_us_) return TimeVerdict::kAheadOfWindow;
  if (ahead_of_wall) return TimeVerdict::kAheadOfWallClock;
  const int64_t wall_elapsed_us = SaturatingDifference(*receive_wall_us, *newest_receive_wall_us_);
  const double allowed_us = static_cast<double>(window_us_) +
                            max_rate_ * static_cast<double>(std::max<int64_t>(wall_elapsed_us, 0));
  return static_cast<double>(ahead_us) <= allowed_us ? TimeVerdict::kPlausible
                                                     : TimeVerdict::kAheadOfWindow;
}

void TimePlausibility::Accept(int64_t utime, std::optional<int64_t> receive_wall_us) {
  STEWART_CHECK(Check(utime, receive_wall_us) == TimeVerdict::kPlausible,
                "only a plausible time can be accepted");
  if (anchored_ && utime < newest_utime_) return;
  anchored_ = true;
  newest_utime_ = utime;
  newest_receive_wall_us_ = receive_wall_us;
}

}  // namespace stewart
