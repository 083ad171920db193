#pragma once
// The device side of the wire protocol (docs/wire-protocol.md): holds the
// latest command under the device watchdog, steps a backend, and produces a
// sensor frame per sample period. No I/O: hw_emulator_main drives it.
#include <cstdint>

#include "stewart/hw_bridge/wire_format.h"
#include "stewart/hw_emulator/device_backend.h"

namespace stewart::hw {

class DeviceEmulator {
 public:
  explicit DeviceEmulator(DeviceBackend* backend) : backend_(backend) {}

  /// A decoded command frame that arrived at device time now_us.
  void OnCommandFrame(const CommandFrame& frame, uint64_t now_us);
  /// A command frame the device rejected (bad CRC, length, field ...).
  void OnRxError() { ++rx_corrupt_; }

  /// One sample period ending at now_us: applies the watchdog, steps the
  /// backend by dt_s, samples it and returns the frame to send.
  SensorFrame Tick(uint64_t now_us, double dt_s);

  const DriveArray& applied_drive() const { return applied_drive_; }
  uint16_t status() const { return status_; }

 private:
  DeviceBackend* backend_;
  bool have_command_ = false;
  CommandFrame command_;
  uint64_t command_rx_us_ = 0;
  DriveArray applied_drive_{};
  uint16_t status_ = kStatusActuatorsOff;
  uint32_t next_seq_ = 0;
  uint32_t rx_corrupt_ = 0;
  uint32_t rx_lost_ = 0;
};

}  // namespace stewart::hw
