#pragma once
// What the emulated device's electronics see: drive commands in, raw
// readings out. The physics behind it is a backend (PlantBackend: plant_sim's
// library), kept apart from the device logic (watchdog, framing, transports)
// so either can change alone and tests can record what the device applied.
#include <array>
#include <cstdint>

#include "stewart/hw_bridge/drive_map.h"

namespace stewart::hw {

/// Raw readings as the myRIO's inputs deliver them.
struct RawReadings {
  std::array<uint16_t, 6> adc{};  ///< leg pot counts
  std::array<int16_t, 3> gyro_raw{};
  std::array<int16_t, 3> accel_raw{};
  uint16_t status = 0;  ///< DeviceStatus fault bits the backend detects (endstop, IMU)
  uint8_t leg_fault_mask = 0;
};

class DeviceBackend {
 public:
  virtual ~DeviceBackend() = default;
  /// Advances the physics by dt_s with `drive` applied (after the device's
  /// watchdog) the whole time.
  virtual void Step(const DriveArray& drive, double dt_s) = 0;
  /// Samples the sensors at the current state.
  virtual RawReadings Sample() = 0;
};

}  // namespace stewart::hw
