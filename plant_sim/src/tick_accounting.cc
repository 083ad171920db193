#include "stewart/plant_sim/tick_accounting.h"

namespace stewart {

TickAccounting::TickAccounting(int64_t utime0, int64_t period_us)
    : utime0_(utime0), period_us_(period_us) {}

TickAccounting::Outcome TickAccounting::OnTickStart(int64_t tick, Clock::time_point deadline,
                                                    Clock::time_point now,
                                                    int64_t last_applied_sample_utime,
                                                    const LoopLatencyTracker& published) {
  const auto period = std::chrono::microseconds(period_us_);
  Outcome outcome;
  const Clock::duration late = now - deadline;
  outcome.late_us = std::chrono::duration_cast<std::chrono::microseconds>(late).count();
  if (late > period) {
    outcome.overrun = true;
    ++counters_.overrun_ticks;
    outcome.log_overrun = counters_.overrun_ticks <= 20 || counters_.overrun_ticks % 100 == 0;
  }
  if (tick > 0) {
    const int64_t previous_sample_utime = utime0_ + (tick - 1) * period_us_;
    if (last_applied_sample_utime < previous_sample_utime) {
      ++counters_.missed_ticks;
      const Clock::duration window = now - published.published_at(tick - 1);
      if (window < period / 2) {
        outcome.missed = Missed::kPlantLate;
        ++counters_.missed_plant_late;
      } else {
        outcome.missed = Missed::kStackLate;
        ++counters_.missed_stack_late;
      }
    }
  }
  return outcome;
}

}  // namespace stewart
