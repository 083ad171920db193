#pragma once
// The emulator's physics: plant_sim's library behind the device's raw
// interface, so that emulator and simulator share one plant model
// (docs/hardware.md, "The emulator").
//
//   drive counts --(inverse of the bridge's DriveMap)--> leg force commands
//     --> stewart::Plant (SUNDIALS; saturation, friction, end-stops, lock)
//     --> stewart::SensorModel (pot noise, IMU with bias and noise; the pots
//         are quantised once, by the device's ADC below)
//     --(inverse of the bridge's LegCalibration / ImuScale)--> raw readings
//
// With the bridge's forward maps on the host side, bridge + emulator equal
// plant_sim up to the drive and ADC count quantisation. A duty within the
// deadband produces no motor force; six legs within it (zero drive: device
// watchdog, enable clear, or a bridge that zeroes the drive) mean the motors
// are unpowered and the lead screws hold every leg (Plant::SetActuatorsOff),
// as plant_sim's "off" fallback does.
//
// A truth with DC-motor actuators (actuators.model dc_motor) takes the duty
// itself: drive counts --(drive signs)--> PWM duty --> stewart::Plant's motor
// model (dead band, bridge drop, back-EMF, rotor inertia, self-locking
// screws, docs/simulation.md); nothing inverts the bridge's map.
#include <memory>

#include "stewart/config/stack_config.h"
#include "stewart/hw_bridge/calibration.h"
#include "stewart/hw_bridge/drive_map.h"
#include "stewart/hw_emulator/device_backend.h"
#include "stewart/plant_sim/disturbance_source.h"
#include "stewart/plant_sim/plant.h"
#include "stewart/plant_sim/sensor_model.h"
#include "stewart/plant_sim/truth.h"

namespace stewart::hw {

struct PlantBackendOptions {
  /// False: sensor noise and biases are zero (the ADC still quantises).
  bool noise = true;
  /// At power-on the legs are held (actuators off) and have been for this
  /// long: the lead-screw locks carry the platform's weight (a lock engaged
  /// this instant would not yet, and the accelerometer would read free fall).
  double power_on_settle_s = 0.1;
};

class PlantBackend final : public DeviceBackend {
 public:
  /// Starts at the truth's initial state with the actuators off (legs held)
  /// until the first non-zero drive; the hold has settled for
  /// options.power_on_settle_s (the platform sags by microns). The physics
  /// come from `truth`; `config` gives `plant_sim` (integrator and
  /// tolerances) and `hw_bridge` (the calibration the device's pots and IMU
  /// are read with, the drive map).
  PlantBackend(const StackConfig& config, const PlantTruth& truth,
               const PlantBackendOptions& options = {});
  PlantBackend(const PlantBackend&) = delete;
  PlantBackend& operator=(const PlantBackend&) = delete;

  void Step(const DriveArray& drive, double dt_s) override;
  RawReadings Sample() override;

  /// Ground truth (evaluation only: a real device has none).
  Vector6d q() const { return plant_.q(); }
  Vector6d qd() const { return plant_.qd(); }
  /// Leg force commands (N) the last Step applied, from the drive (ideal
  /// force source; a DC-motor plant's input is plant().inputs().duty).
  const Vector6d& force_cmd_n() const { return plant_.inputs().force_cmd_n; }
  bool actuators_off() const { return plant_.actuators_off(); }
  const Plant& plant() const { return plant_; }

 private:
  Plant plant_;
  SensorModel sensors_;
  DisturbanceSource disturbance_;
  LegCalibration calibration_;
  ImuScale imu_;
  void StepIdealForceSource(const DriveArray& drive);

  DriveMap drive_map_;
  double adc_max_;
  double min_length_m_;
  double max_length_m_;
};

}  // namespace stewart::hw
