#include "stewart/plant_sim/loop_latency_tracker.h"

namespace stewart {

LoopLatencyTracker::LoopLatencyTracker(int64_t utime0, int64_t period_us)
    : utime0_(utime0), period_us_(period_us) {}

void LoopLatencyTracker::OnPublished(int64_t tick, int64_t sample_utime, Clock::time_point at) {
  sample_utime_[Slot(tick)] = sample_utime;
  published_at_[Slot(tick)] = at;
}

std::optional<int64_t> LoopLatencyTracker::OnCommand(int64_t sample_utime, int64_t current_tick,
                                                     Clock::time_point now) {
  if (sample_utime <= newest_timed_sample_utime_ || sample_utime < utime0_) return std::nullopt;
  const int64_t tick = (sample_utime - utime0_) / period_us_;
  if (tick > current_tick || sample_utime_[Slot(tick)] != sample_utime) return std::nullopt;
  newest_timed_sample_utime_ = sample_utime;
  return std::chrono::duration_cast<std::chrono::microseconds>(now - published_at_[Slot(tick)])
      .count();
}

LoopLatencyTracker::Clock::time_point LoopLatencyTracker::published_at(int64_t tick) const {
  return published_at_[Slot(tick)];
}

}  // namespace stewart
