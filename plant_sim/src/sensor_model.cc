#include "stewart/plant_sim/sensor_model.h"

#include <cmath>

#include "stewart/model/imu.h"
#include "stewart/model/rotation.h"

namespace stewart {

double LegAdcResolution(const SensorConfig& sensors, const ActuatorConfig& actuators) {
  return LegAdcStepM(sensors, actuators.stroke_m);
}

Vector6d QuantiseLegLength(const SensorConfig& sensors, const ActuatorConfig& actuators,
                           const Vector6d& leg_length_m) {
  const double lsb_m = LegAdcResolution(sensors, actuators);
  if (lsb_m <= 0.0) return leg_length_m;
  const double max_code = std::ldexp(1.0, sensors.leg_adc_bits) - 1.0;
  Vector6d out;
  for (int i = 0; i < kNumLegs; ++i) {
    const double code =
        std::clamp(std::round((leg_length_m(i) - actuators.min_length_m) / lsb_m), 0.0, max_code);
    out(i) = actuators.min_length_m + code * lsb_m;
  }
  return out;
}

SensorModel::SensorModel(const SensorConfig& sensors, const ActuatorConfig& actuators,
                         double gravity_mps2, const SensorTruth& errors)
    : sensors_(sensors),
      actuators_(actuators),
      errors_(errors),
      imu_from_P_(RotationFromEuler(errors.imu_misalignment_rad).transpose()),
      gravity_mps2_(gravity_mps2),
      rng_(sensors.seed) {}

SensorReading SensorModel::Sample(const Vector6d& q, const Vector6d& qd, const Vector6d& qdd,
                                  const Vector6d& leg_length_m) {
  SensorReading r;
  // Fixed draw order (legs, gyro, accel, orientation) keeps a seed's sequence
  // independent of which values are zero.
  Vector6d leg_noisy_m;
  constexpr double kPi = 3.141592653589793;
  for (int i = 0; i < kNumLegs; ++i) {
    const double u = (leg_length_m(i) - actuators_.min_length_m) / actuators_.stroke_m;
    leg_noisy_m(i) = errors_.leg_scale(i) * leg_length_m(i) + errors_.leg_offset_m(i) +
                     errors_.leg_nonlinearity_m * std::sin(kPi * u) +
                     sensors_.leg_pot_noise_std_m * Gaussian();
  }
  r.leg_length_m = QuantiseLegLength(sensors_, actuators_, leg_noisy_m);

  r.gyro_radps = errors_.gyro_scale.cwiseProduct(imu_from_P_ * BodyAngularVelocity(q, qd)) +
                 sensors_.gyro_bias_radps;
  for (int i = 0; i < 3; ++i) r.gyro_radps(i) += sensors_.gyro_noise_std_radps * Gaussian();

  r.accel_mps2 =
      errors_.accel_scale.cwiseProduct(
          imu_from_P_ * ImuSpecificForce(q, qd, qdd, sensors_.imu_offset_in_P_m, gravity_mps2_)) +
      sensors_.accel_bias_mps2;
  for (int i = 0; i < 3; ++i) r.accel_mps2(i) += sensors_.accel_noise_std_mps2 * Gaussian();

  r.has_orientation = sensors_.has_orientation;
  if (r.has_orientation) {
    r.orientation_rpy_rad = q.tail<3>();
    for (int i = 0; i < 3; ++i) {
      r.orientation_rpy_rad(i) += sensors_.orientation_noise_std_rad * Gaussian();
    }
  }
  return r;
}

}  // namespace stewart
