#pragma once
// The actuator procedure's device through the hardware path, in process: the
// device emulator (hw_bridge/emulator: DeviceEmulator on a PlantBackend, the
// truth's physics) behind hw_bridge's library in bring-up mode (HwBridge
// with BringupOptions), joined by encoded and decoded wire frames instead of
// a transport, on one simulated clock (as tests/hw_bridge/emulator_test.cc's
// BridgePlusEmulatorEqualsPlantSim). What differs from --plant sim: the
// device's 12-bit ADC after the sensor model, the duty's quantisation to
// drive counts, the command's latency, the bridge's guard and echo.
#include <cstdint>
#include <memory>

#include "stewart/config/stack_config.h"
#include "stewart/hw_bridge/bridge.h"
#include "stewart/hw_emulator/device_emulator.h"
#include "stewart/hw_emulator/plant_backend.h"
#include "stewart/identify/actuator_device.h"

namespace stewart::identify {

struct EmulatorDeviceOptions {
  bool noise = true;
  /// A sensor frame reaches the bridge this long after its sample.
  int64_t sensor_delay_us = 40;
  /// A duty command reaches the device this long after the sample it
  /// answers (the procedure and the link; < one sample period).
  int64_t command_delay_us = 300;
};

class EmulatorDevice final : public ActuatorDevice {
 public:
  /// Throws IdentificationError when the truth's legs are not DC motors.
  EmulatorDevice(const StackConfig& config, const PlantTruth& truth,
                 const hw::BringupOptions& bringup, const EmulatorDeviceOptions& options = {});

  ActuatorSample NextSample() override;
  void SetDuty(int64_t sample_utime, const Vector6d& duty) override;

  const hw::HwBridge& bridge() const { return bridge_; }
  const hw::PlantBackend& backend() const { return *backend_; }
  /// Duty commands the bridge did not accept.
  long rejected_commands() const { return rejected_; }

 private:
  void SendFrame(uint64_t device_us);

  std::unique_ptr<hw::PlantBackend> backend_;
  hw::DeviceEmulator device_;
  hw::HwBridge bridge_;
  EmulatorDeviceOptions options_;
  uint64_t period_us_;
  uint64_t device_us_;  // the latest sample's device time
  long rejected_ = 0;
};

}  // namespace stewart::identify
