#pragma once
// When the emulated device takes its samples, in device time (us): on the
// exact period grid, as the myRIO's FPGA loop latches them. The device clock
// starts at an epoch of its own (power-on), so the host must map it
// (docs/wire-protocol.md, "Time"). No I/O: the emulator node asks it.
#include <cstdint>

namespace stewart::hw {

class SampleSchedule {
 public:
  /// The device clock at the emulator's start.
  static constexpr uint64_t kDeviceEpochUs = 5'000'000;
  /// Further behind than this many periods, the device skips the missed
  /// samples instead of sending a burst (the physics still runs through the
  /// gap, in device time).
  static constexpr uint64_t kMaxBacklogPeriods = 10;

  /// drop_every > 0: every drop_every-th sample is taken but not sent (link tests).
  SampleSchedule(uint64_t period_us, int drop_every);

  uint64_t next_tick_us() const { return next_tick_us_; }
  bool Due(uint64_t now_us) const { return now_us >= next_tick_us_; }
  /// Further behind than kMaxBacklogPeriods: the device's loop was not
  /// running (descheduled, stopped), and what its receiver queued meanwhile
  /// arrived at times it cannot tell.
  bool Stalled(uint64_t now_us) const {
    return now_us > next_tick_us_ + kMaxBacklogPeriods * period_us_;
  }

  struct Sample {
    uint64_t time_us = 0;  ///< on the period grid
    bool send = true;
  };
  /// Takes the next sample at device time now_us (call while Due).
  Sample Take(uint64_t now_us);

  uint64_t ticks() const { return ticks_; }
  uint64_t skipped() const { return skipped_; }

 private:
  uint64_t period_us_;
  int drop_every_;
  uint64_t next_tick_us_;
  uint64_t ticks_ = 0;
  uint64_t skipped_ = 0;
};

}  // namespace stewart::hw
