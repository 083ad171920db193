#pragma once
// Lockstep pacing: after publishing a tick's sample the plant waits for its
// answer, re-sends the sample when nothing moves, and gives up after the
// lockstep timeout. No LCM: the node asks Poll() what to do and waits on its
// socket for as long as it says.
//
// Re-sending the stored sample (never a new draw, which would change the
// noise sequence) covers a stack that subscribes after the plant started
// (tick 0, every startup_republish_s) and a datagram the kernel delayed or
// lost later (every kStallResend): lockstep has nothing else to move the loop
// along, and a receiver that already has the sample rejects the copy by its
// utime.
#include <chrono>
#include <cstdint>

namespace stewart {

class LockstepPacing {
 public:
  using Clock = std::chrono::steady_clock;
  static constexpr std::chrono::milliseconds kStallResend{200};
  /// The longest single wait, so a stop signal is seen promptly.
  static constexpr int kMaxWaitMs = 50;

  /// startup_republish_s = 0: tick 0 is never re-sent.
  LockstepPacing(double timeout_s, double startup_republish_s);

  /// The sample of `tick` was published at `now`; its answer is awaited.
  void StartWaiting(int64_t tick, Clock::time_point now);

  struct Step {
    bool timed_out = false;  ///< no answer within the timeout: stop
    bool resend = false;     ///< publish the stored sample again now
    int wait_ms = 0;         ///< then wait on the socket this long
  };
  Step Poll(Clock::time_point now);

 private:
  Clock::duration timeout_;
  Clock::duration startup_republish_;
  bool startup_republish_enabled_;
  int64_t tick_ = 0;
  Clock::time_point waiting_since_{};
  Clock::time_point last_sent_{};
};

}  // namespace stewart
