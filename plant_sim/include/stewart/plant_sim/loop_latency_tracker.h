#pragma once
// The loop's latency as the plant sees it: from publishing sample k to
// receiving the first command derived from it. Both ends are read on the
// plant's own wall clock, so no clock has to be shared with the stack. No LCM:
// the node passes the instants in.
#include <array>
#include <chrono>
#include <cstdint>
#include <optional>

namespace stewart {

class LoopLatencyTracker {
 public:
  using Clock = std::chrono::steady_clock;
  /// Samples remembered; a command for an older one is not timed.
  static constexpr int kRing = 64;

  /// Tick k's sample carries utime0 + k * period_us.
  LoopLatencyTracker(int64_t utime0, int64_t period_us);

  void OnPublished(int64_t tick, int64_t sample_utime, Clock::time_point at);

  /// A command for `sample_utime` received at `now`, while `current_tick` is
  /// the plant's tick. Returns its latency (us) when it is the first command
  /// for a remembered sample newer than every sample timed so far; nullopt
  /// for a repeat, an older answer, or a sample not (or no longer) in the ring.
  std::optional<int64_t> OnCommand(int64_t sample_utime, int64_t current_tick,
                                   Clock::time_point now);

  /// When tick `tick` (>= 0, among the last kRing) was published.
  Clock::time_point published_at(int64_t tick) const;

 private:
  static size_t Slot(int64_t tick) { return static_cast<size_t>(tick % kRing); }

  int64_t utime0_;
  int64_t period_us_;
  std::array<int64_t, kRing> sample_utime_{};
  std::array<Clock::time_point, kRing> published_at_{};
  int64_t newest_timed_sample_utime_ = -1;
};

}  // namespace stewart
