#include "stewart/hw_emulator/device_emulator.h"

#include <algorithm>

namespace stewart::hw {

CommandAcceptance DeviceEmulator::OnCommandFrame(const CommandFrame& frame, uint64_t now_us) {
  // The frame in force still drives until its watchdog expires (as in
  // DriveFrom); one stamped before its own arrival time is still young.
  const bool current_drives =
      have_command_ && (now_us < command_rx_us_ || now_us - command_rx_us_ < command_.watchdog_us);
  const CommandAcceptance verdict = sessions_.Accept(frame, current_drives);
  if (!Applies(verdict)) return verdict;
  AdvanceTo(now_us);
  have_command_ = true;
  command_ = frame;
  // A frame stamped before the physics' time (it waited in the receive
  // queue while a sample was taken) acts from now on, never in the past.
  command_rx_us_ = std::max(now_us, physics_us_);
  return verdict;
}

DriveArray DeviceEmulator::DriveFrom(uint64_t t_us, uint16_t* status) const {
  *status = 0;
  if (!have_command_) {
    *status = kStatusActuatorsOff;
  } else if (t_us - command_rx_us_ >= command_.watchdog_us) {
    // In force up to and including rx + watchdog_us, zero after it.
    *status = kStatusWatchdog;
  } else if ((command_.flags & kCommandEnable) == 0) {
    *status = kStatusActuatorsOff;
  }
  return *status == 0 ? command_.drive : DriveArray{};
}

void DeviceEmulator::AdvanceTo(uint64_t t_us) {
  if (!started_) {
    started_ = true;
    physics_us_ = t_us;
    return;
  }
  while (physics_us_ < t_us) {
    uint16_t status = 0;
    applied_drive_ = DriveFrom(physics_us_, &status);
    uint64_t end_us = t_us;
    if (status == 0) end_us = std::min(end_us, command_rx_us_ + command_.watchdog_us);
    backend_->Step(applied_drive_, static_cast<double>(end_us - physics_us_) * 1e-6);
    physics_us_ = end_us;
  }
}

SensorFrame DeviceEmulator::Tick(uint64_t now_us) {
  AdvanceTo(now_us);
  uint16_t status = 0;
  if (!have_command_) {
    status = kStatusActuatorsOff;
  } else if (physics_us_ - command_rx_us_ > command_.watchdog_us) {
    status = kStatusWatchdog;
  } else if ((command_.flags & kCommandEnable) == 0) {
    status = kStatusActuatorsOff;
  }
  const RawReadings raw = backend_->Sample();

  SensorFrame frame;
  frame.seq = next_seq_++;
  frame.device_time_us = physics_us_;
  frame.adc = raw.adc;
  frame.gyro_raw = raw.gyro_raw;
  frame.accel_raw = raw.accel_raw;
  frame.status = static_cast<uint16_t>(status | raw.status);
  frame.leg_fault_mask = raw.leg_fault_mask;
  if (raw.leg_fault_mask != 0) frame.status |= kStatusLegFault;
  frame.last_command_seq = have_command_ ? command_.seq : 0;
  frame.command_age_us = have_command_ ? static_cast<uint32_t>(physics_us_ - command_rx_us_) : 0;
  frame.applied_drive = applied_drive_;
  frame.rx_corrupt = rx_corrupt_;
  frame.rx_lost = sessions_.rx_lost();
  frame.command_session = sessions_.session();
  frame.rx_session_rejected = sessions_.rx_session_rejected();
  return frame;
}

}  // namespace stewart::hw
