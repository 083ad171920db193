#include "stewart/hw_emulator/device_emulator.h"

namespace stewart::hw {

void DeviceEmulator::OnCommandFrame(const CommandFrame& frame, uint64_t now_us) {
  if (have_command_) {
    const auto gap = static_cast<int32_t>(frame.seq - command_.seq);
    if (gap <= 0) return;  // duplicate or reordered: the newer one is in force
    rx_lost_ += static_cast<uint32_t>(gap - 1);
  }
  have_command_ = true;
  command_ = frame;
  command_rx_us_ = now_us;
}

SensorFrame DeviceEmulator::Tick(uint64_t now_us, double dt_s) {
  status_ = 0;
  if (!have_command_) {
    status_ |= kStatusActuatorsOff;
  } else if (now_us - command_rx_us_ > command_.watchdog_us) {
    status_ |= kStatusWatchdog;
  } else if ((command_.flags & kCommandEnable) == 0) {
    status_ |= kStatusActuatorsOff;
  }
  if (status_ == 0) {
    applied_drive_ = command_.drive;
  } else {
    applied_drive_.fill(0);
  }
  backend_->Step(applied_drive_, dt_s);
  const RawReadings raw = backend_->Sample();

  SensorFrame frame;
  frame.seq = next_seq_++;
  frame.device_time_us = now_us;
  frame.adc = raw.adc;
  frame.gyro_raw = raw.gyro_raw;
  frame.accel_raw = raw.accel_raw;
  frame.status = static_cast<uint16_t>(status_ | raw.status);
  frame.leg_fault_mask = raw.leg_fault_mask;
  if (raw.leg_fault_mask != 0) frame.status |= kStatusLegFault;
  frame.last_command_seq = have_command_ ? command_.seq : 0;
  frame.command_age_us = have_command_ ? static_cast<uint32_t>(now_us - command_rx_us_) : 0;
  frame.applied_drive = applied_drive_;
  frame.rx_corrupt = rx_corrupt_;
  frame.rx_lost = rx_lost_;
  return frame;
}

}  // namespace stewart::hw
