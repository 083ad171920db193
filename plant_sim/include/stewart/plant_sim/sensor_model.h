#pragma once
// Simulated sensors (docs/simulation.md, "Sensors"): leg potentiometers read
// by an ADC, and an IMU on the platform. The noise comes from one seeded
// generator drawn in a fixed order, so a seed gives one exact sequence.
#include <random>

#include "stewart/model/actuator_params.h"
#include "stewart/model/sensor_params.h"
#include "stewart/model/types.h"
#include "stewart/plant_sim/truth.h"

namespace stewart {

struct SensorReading {
  Vector6d leg_length_m = Vector6d::Zero();  ///< joint to joint (m)
  Vector3d gyro_radps = Vector3d::Zero();    ///< {P} axes
  Vector3d accel_mps2 = Vector3d::Zero();    ///< specific force, {P} axes
  bool has_orientation = false;
  Vector3d orientation_rpy_rad = Vector3d::Zero();  ///< of {P} in {B}
};

/// Leg-length step of the potentiometer ADC: stroke / (2^bits - 1) (m);
/// 0 when leg_adc_bits = 0 (no quantisation).
double LegAdcResolution(const SensorConfig& sensors, const ActuatorConfig& actuators);

/// The ADC: rounds to the nearest code over [l_min, l_min + stroke] and
/// saturates at both ends of the range. Identity when leg_adc_bits = 0.
Vector6d QuantiseLegLength(const SensorConfig& sensors, const ActuatorConfig& actuators,
                           const Vector6d& leg_length_m);

class SensorModel {
 public:
  /// `errors`: the truth's sensor errors (none by default).
  SensorModel(const SensorConfig& sensors, const ActuatorConfig& actuators, double gravity_mps2,
              const SensorTruth& errors = SensorTruth{});

  /// One sample of the true motion (q, qd, qdd at one instant), with
  /// u = (L - l_min) / stroke and R_m the IMU's misalignment (truth.h):
  ///   legs   = ADC(s_L L(q) + o_L + a sin(pi u) + n_L),  n_L ~ N(0, leg_pot_noise_std_m^2)
  ///   gyro   = s_g R_m^T BodyAngularVelocity + b_g + n_g
  ///   accel  = s_a R_m^T ImuSpecificForce(at imu_offset_in_P_m) + b_a + n_a
  ///   orient = [phi theta psi] + n_o           (only if has_orientation)
  SensorReading Sample(const Vector6d& q, const Vector6d& qd, const Vector6d& qdd,
                       const Vector6d& leg_length_m);

  const SensorConfig& config() const { return sensors_; }

 private:
  double Gaussian() { return standard_normal_(rng_); }

  SensorConfig sensors_;
  ActuatorConfig actuators_;
  SensorTruth errors_;
  Matrix3d imu_from_P_;  // R_m^T
  double gravity_mps2_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> standard_normal_{0.0, 1.0};
};

}  // namespace stewart
