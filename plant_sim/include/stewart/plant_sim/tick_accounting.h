#pragma once
// Real time: which ticks went wrong and whose fault it was
// (docs/simulation.md, "Real-time figures"). No LCM: the node passes the
// instants in and copies the counters into its heartbeat.
//
// An overrun is a tick started more than one period after its deadline: the
// simulator itself fell behind. A missed tick is one whose previous sample
// got no command before this tick, so the stale command stays applied. It is
// the plant's fault when the plant published that sample so late that the
// stack had less than half a period left to answer it (the plant catches up
// on the wall clock); otherwise the stack's.
#include <chrono>
#include <cstdint>

#include "stewart/plant_sim/loop_latency_tracker.h"

namespace stewart {

struct TickCounters {
  int64_t overrun_ticks = 0;
  int64_t missed_ticks = 0;
  int64_t missed_plant_late = 0;
  int64_t missed_stack_late = 0;
};

class TickAccounting {
 public:
  using Clock = std::chrono::steady_clock;

  enum class Missed { kNone, kStackLate, kPlantLate };
  struct Outcome {
    int64_t late_us = 0;  ///< how long after its deadline the tick started
    bool overrun = false;
    /// An overrun worth a log line: the first ones, then one in a hundred.
    bool log_overrun = false;
    Missed missed = Missed::kNone;
  };

  /// Tick k's sample carries utime0 + k * period_us.
  TickAccounting(int64_t utime0, int64_t period_us);

  /// Tick `tick`, due at `deadline`, starts at `now`; the newest applied
  /// command answered `last_applied_sample_utime`; `published` knows when the
  /// previous sample went out.
  Outcome OnTickStart(int64_t tick, Clock::time_point deadline, Clock::time_point now,
                      int64_t last_applied_sample_utime, const LoopLatencyTracker& published);

  const TickCounters& counters() const { return counters_; }

 private:
  int64_t utime0_;
  int64_t period_us_;
  TickCounters counters_;
};

}  // namespace stewart
