#include "stewart/hw_emulator/plant_backend.h"

#include <algorithm>
#include <cmath>

#include "stewart/hw_bridge/wire_format.h"

namespace stewart::hw {
namespace {

// STATUS_ENDSTOP: a leg within this of a stroke end (docs/wire-protocol.md).
constexpr double kEndstopBandM = 5e-4;

SensorConfig SensorsOf(const SensorConfig& sensors, bool noise) {
  SensorConfig s = sensors;
  // The device's own ADC (Sample) quantises the pots; the sensor model's
  // (plant_sim's stand-in for it) would quantise them twice, and the two
  // grids together biased the actuator identification's rotor mass by 4-7 %.
  s.leg_adc_bits = 0;
  if (!noise) {
    s.leg_pot_noise_std_m = 0.0;
    s.gyro_noise_std_radps = 0.0;
    s.gyro_bias_radps.setZero();
    s.accel_noise_std_mps2 = 0.0;
    s.accel_bias_mps2.setZero();
    s.orientation_noise_std_rad = 0.0;
  }
  return s;
}

}  // namespace

PlantBackend::PlantBackend(const StackConfig& config, const PlantTruth& truth,
                           const PlantBackendOptions& options)
    : plant_(PlantModelOf(truth, config), OdeOptionsFrom(config.plant_sim)),
      sensors_(SensorsOf(truth.sensors, options.noise), truth.actuators,
               truth.platform.gravity_mps2, truth.sensor_errors),
      disturbance_(truth.disturbance, truth.sensors.seed),
      // The device's pots read with the stack's calibration: a truth with other
      // stroke ends shows up as a calibration error, as on the prototype.
      calibration_(config.hw_bridge, config.actuators.min_length_m, config.actuators.stroke_m),
      imu_(config.hw_bridge),
      drive_map_(config.hw_bridge, config.actuators.force_limit_n),
      adc_max_(config.hw_bridge.adc_max_count),
      min_length_m_(config.actuators.min_length_m),
      max_length_m_(config.actuators.min_length_m + config.actuators.stroke_m) {
  plant_.Reset(0.0, truth.initial_pose, truth.initial_velocity);
  // Powered off until the first command: the lead screws hold the legs.
  plant_.SetActuatorsOff(true);
  if (options.power_on_settle_s > 0.0) plant_.Advance(options.power_on_settle_s);
}

void PlantBackend::Step(const DriveArray& drive, double dt_s) {
  if (!(dt_s > 0.0)) return;
  if (plant_.model().actuators.kind == ActuatorKind::kDcMotor) {
    // The device's legs as they are: the duty drives the motors, whose
    // physics (dead band, back-EMF, self-locking screws) is the plant's.
    plant_.SetActuatorsOff(false);
    plant_.SetDutyCommand(drive_map_.Duty(drive));
  } else {
    StepIdealForceSource(drive);
  }
  plant_.SetExternalWrench(disturbance_.WrenchAt(plant_.time_s()));
  plant_.Advance(dt_s);
}

void PlantBackend::StepIdealForceSource(const DriveArray& drive) {
  const std::array<bool, 6> locked = drive_map_.Locked(drive);
  const bool all_locked = std::all_of(locked.begin(), locked.end(), [](bool l) { return l; });
  plant_.SetActuatorsOff(all_locked);
  if (!all_locked) plant_.SetForceCommand(drive_map_.DriveToForce(drive));
}

RawReadings PlantBackend::Sample() {
  // The acceleration under the drive held over the interval just ended, as
  // plant_sim samples its accelerometer.
  const PlantRates& rates = plant_.EvaluateRates();
  const Vector6d lengths = rates.terms.leg_length_m;
  const SensorReading r =
      sensors_.Sample(plant_.q(), plant_.qd(), rates.x_dot.segment<6>(6), lengths);
  RawReadings raw;
  for (int i = 0; i < kNumLegs; ++i) {
    if (lengths(i) < min_length_m_ + kEndstopBandM || lengths(i) > max_length_m_ - kEndstopBandM) {
      raw.status |= kStatusEndstop;
    }
    // The pot's voltage, digitised by the myRIO: the inverse of the bridge's
    // two-point calibration, rounded to a count and clipped to the AI range.
    const double counts = std::round(calibration_.AdcCounts(i, r.leg_length_m(i)));
    raw.adc[static_cast<std::size_t>(i)] = static_cast<uint16_t>(std::clamp(counts, 0.0, adc_max_));
  }
  const bool gyro_ok = imu_.GyroRaw(r.gyro_radps, &raw.gyro_raw);
  const bool accel_ok = imu_.AccelRaw(r.accel_mps2, &raw.accel_raw);
  if (!gyro_ok || !accel_ok) raw.status |= kStatusImuFault;
  return raw;
}

}  // namespace stewart::hw
