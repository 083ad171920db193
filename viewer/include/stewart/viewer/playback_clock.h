#pragma once
// The stack time a log is played at: play, pause, a rate, a seek. Wall time
// is passed in (steady clock) so tests need no sleeps.
#include <chrono>
#include <cstdint>

namespace stewart::viewer {

class PlaybackClock {
 public:
  using Clock = std::chrono::steady_clock;
  static constexpr double kMinRate = 0.1;
  static constexpr double kMaxRate = 10.0;

  /// Paused at start_us. Throws InputError unless start_us <= end_us.
  PlaybackClock(int64_t start_us, int64_t end_us);

  void Play(Clock::time_point now);
  void Pause(Clock::time_point now);
  /// Throws InputError outside [kMinRate, kMaxRate].
  void SetRate(double rate, Clock::time_point now);
  /// Jumps to utime_us, clamped to the log's range; keeps playing or paused.
  void Seek(int64_t utime_us, Clock::time_point now);

  /// The stack time at `now`; pauses itself at the end of the log.
  int64_t TimeAt(Clock::time_point now);
  bool playing() const { return playing_; }
  double rate() const { return rate_; }
  int64_t start_us() const { return start_us_; }
  int64_t end_us() const { return end_us_; }

 private:
  int64_t Advance(Clock::time_point now) const;

  int64_t start_us_, end_us_;
  int64_t anchor_utime_us_;  ///< stack time at anchor_wall_
  Clock::time_point anchor_wall_{};
  bool playing_ = false;
  double rate_ = 1.0;
};

}  // namespace stewart::viewer
