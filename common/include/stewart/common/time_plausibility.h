#pragma once
// Whether a message's stack time is plausible for its receiver, so that one
// message with a far-off utime (forged, or from a stale process) cannot
// become the time a process acts on.
//
// Stack time is the plant's clock carried in messages (docs/messages.md). In
// real time it runs at the wall rate from the wall clock (plant_sim starts it
// there, hw_bridge maps the device's clock onto it); in lockstep it starts at
// 0 and runs as fast as the stack answers (10-50x the wall rate). A receiver
// therefore maps stack time from what it has accepted, not from its own
// clock:
//
//   - a time within `window` of the newest accepted time is plausible;
//   - further ahead only with a receive time (the wall clock at which the
//     message arrived, from the receive path) for it and for the newest
//     accepted message: then up to `max_rate` stack seconds per wall second
//     elapsed since the newest accepted message (a plant restarted in real
//     time, a device link back after a dropout), and never ahead of the
//     receive time by more than the window (stack time is never ahead of the
//     wall clock on the stack's host);
//   - further behind is never plausible.
//
// Before anything is accepted, every time is plausible except one ahead of
// the receive time by more than the window.
//
// Without receive times (replay, the in-process closed loop) only message
// times decide, so the same messages always give the same verdicts; a live
// process decides the same except after a gap longer than the window, which
// only the receive time can tell from a forgery.
//
// LCM-free and allocation-free: every process's library and plant-side
// classes can hold one.
#include <cstdint>
#include <optional>

namespace stewart {

/// The bus's time bounds (config `lcm.time_window_s`, `lcm.max_time_rate`).
struct TimePlausibilityParams {
  /// How far a message's stack time may be from the newest accepted one
  /// without a receive time to justify it (s). Larger than every stale age
  /// and sample gap of the stack.
  double window_s = 1.0;
  /// The fastest stack time runs, in stack seconds per wall second (lockstep
  /// reaches 10-50; real time 1).
  double max_rate = 100.0;
};

enum class TimeVerdict {
  kPlausible,
  kBehindWindow,      ///< older than the newest accepted time by more than the window
  kAheadOfWindow,     ///< newer than the newest accepted time allows
  kAheadOfWallClock,  ///< ahead of its own receive time by more than the window
};

/// Short snake_case name, e.g. "ahead_of_window".
const char* ToString(TimeVerdict verdict);

class TimePlausibility {
 public:
  /// Throws std::logic_error unless window_s > 0 and max_rate >= 1.
  explicit TimePlausibility(const TimePlausibilityParams& params);

  /// The verdict on a message's `utime`, received at `receive_wall_us` (the
  /// wall clock in us since the epoch; nullopt in replay). Moves nothing.
  TimeVerdict Check(int64_t utime, std::optional<int64_t> receive_wall_us) const;

  /// A message of the receiver's time source was accepted at `utime`: the
  /// newest accepted time moves to it if later (never back). The caller
  /// checked it first (STEWART_CHECK'd).
  void Accept(int64_t utime, std::optional<int64_t> receive_wall_us);

  bool anchored() const { return anchored_; }
  /// The newest accepted time (us); meaningful once anchored().
  int64_t newest_utime() const { return newest_utime_; }
  int64_t window_us() const { return window_us_; }

 private:
  int64_t window_us_;
  double max_rate_;
  bool anchored_ = false;
  int64_t newest_utime_ = 0;
  /// Receive time of the newest accepted message, when it had one.
  std::optional<int64_t> newest_receive_wall_us_;
};

}  // namespace stewart
