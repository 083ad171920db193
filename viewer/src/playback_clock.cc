#include "stewart/viewer/playback_clock.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "stewart/common/check.h"

namespace stewart::viewer {

PlaybackClock::PlaybackClock(int64_t start_us, int64_t end_us)
    : start_us_(start_us), end_us_(end_us), anchor_utime_us_(start_us) {
  STEWART_CHECK_INPUT(start_us <= end_us, "log", "ends before it starts");
}

int64_t PlaybackClock::Advance(Clock::time_point now) const {
  if (!playing_) return anchor_utime_us_;
  const double elapsed_s = std::chrono::duration<double>(now - anchor_wall_).count();
  const auto advanced =
      anchor_utime_us_ + static_cast<int64_t>(std::llround(elapsed_s * rate_ * 1e6));
  return std::clamp(advanced, start_us_, end_us_);
}

void PlaybackClock::Play(Clock::time_point now) {
  anchor_utime_us_ = Advance(now);
  // Play at the end starts over, as a media player does.
  if (anchor_utime_us_ >= end_us_) anchor_utime_us_ = start_us_;
  anchor_wall_ = now;
  playing_ = true;
}

void PlaybackClock::Pause(Clock::time_point now) {
  anchor_utime_us_ = Advance(now);
  anchor_wall_ = now;
  playing_ = false;
}

void PlaybackClock::SetRate(double rate, Clock::time_point now) {
  STEWART_CHECK_INPUT(std::isfinite(rate) && rate >= kMinRate && rate <= kMaxRate, "rate",
                      "must be within [0.1, 10], got " + std::to_string(rate));
  anchor_utime_us_ = Advance(now);
  anchor_wall_ = now;
  rate_ = rate;
}

void PlaybackClock::Seek(int64_t utime_us, Clock::time_point now) {
  anchor_utime_us_ = std::clamp(utime_us, start_us_, end_us_);
  anchor_wall_ = now;
}

int64_t PlaybackClock::TimeAt(Clock::time_point now) {
  const int64_t t = Advance(now);
  if (playing_ && t >= end_us_) {
    playing_ = false;
    anchor_utime_us_ = end_us_;
    anchor_wall_ = now;
  }
  return t;
}

}  // namespace stewart::viewer
