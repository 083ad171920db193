#include "stewart/hw_emulator/sample_schedule.h"

namespace stewart::hw {

SampleSchedule::SampleSchedule(uint64_t period_us, int drop_every)
    : period_us_(period_us), drop_every_(drop_every), next_tick_us_(kDeviceEpochUs + period_us) {}

SampleSchedule::Sample SampleSchedule::Take(uint64_t now_us) {
  if (Stalled(now_us)) {
    const uint64_t missed = (now_us - next_tick_us_) / period_us_;
    next_tick_us_ += missed * period_us_;
    skipped_ += missed;
  }
  Sample sample;
  sample.time_us = next_tick_us_;
  ++ticks_;
  sample.send = drop_every_ <= 0 || ticks_ % static_cast<uint64_t>(drop_every_) != 0;
  next_tick_us_ += period_us_;
  return sample;
}

}  // namespace stewart::hw
