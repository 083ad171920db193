#pragma once
// The actuator procedure's device in process: plant_sim's Plant (the truth's
// physics, DC-motor legs) and SensorModel (pot noise and ADC), sampled at
// sensors.rate_hz, no LCM (stewart_identify --mode actuators --plant sim).
// Like the real device it starts unpowered with the screws holding the legs,
// applies a duty from the instant it is set plus the truth's latency, and
// reports which duty it applied from when.
#include <array>

#include "stewart/config/stack_config.h"
#include "stewart/identify/actuator_device.h"
#include "stewart/plant_sim/plant.h"
#include "stewart/plant_sim/sensor_model.h"

namespace stewart::identify {

struct PlantDeviceOptions {
  bool noise = true;  ///< false: no pot noise (the ADC still quantises)
  /// Unpowered and held this long before the first sample: the screws carry
  /// the platform's weight (as the emulator's power-on).
  double power_on_settle_s = 0.1;
};

class PlantDevice final : public ActuatorDevice {
 public:
  /// Throws IdentificationError when the truth's legs are not DC motors.
  PlantDevice(const StackConfig& config, const PlantTruth& truth,
              const PlantDeviceOptions& options = {});

  ActuatorSample NextSample() override;
  void SetDuty(int64_t sample_utime, const Vector6d& duty) override;

  /// Ground truth, for tests.
  const Plant& plant() const { return plant_; }
  /// Every duty set, for tests.
  long duty_commands() const { return duty_commands_; }

 private:
  struct Pending {
    int64_t apply_utime = 0;
    Vector6d duty = Vector6d::Zero();
  };

  Plant plant_;
  SensorModel sensors_;
  int64_t period_us_;
  int64_t delay_us_;
  int64_t utime_ = 0;  // the current sample's time
  bool powered_ = false;
  Vector6d applied_ = Vector6d::Zero();
  int64_t applied_since_ = 0;
  // Duties not yet in effect (the truth's latency), oldest first.
  std::array<Pending, 64> pending_{};
  int pending_head_ = 0;
  int pending_count_ = 0;
  long duty_commands_ = 0;
};

}  // namespace stewart::identify
