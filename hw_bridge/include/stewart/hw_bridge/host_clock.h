#pragma once
#include <chrono>
#include <cstdint>

namespace stewart::hw {

/// The host time base of hw_bridge (us): the wall clock (Unix epoch) read
/// once at start, advanced by the monotonic clock, so it is comparable with
/// lcm-logger timestamps yet never jumps when NTP steps the wall clock.
class HostClock {
 public:
  HostClock()
      : start_steady_(std::chrono::steady_clock::now()),
        start_epoch_us_(std::chrono::duration_cast<std::chrono::microseconds>(
                            std::chrono::system_clock::now().time_since_epoch())
                            .count()) {}

  int64_t NowMicros() const {
    return start_epoch_us_ + std::chrono::duration_cast<std::chrono::microseconds>(
                                 std::chrono::steady_clock::now() - start_steady_)
                                 .count();
  }

 private:
  std::chrono::steady_clock::time_point start_steady_;
  int64_t start_epoch_us_;
};

}  // namespace stewart::hw
