#pragma once
// The sensors as simulated and as expected (config section `sensors`).
#include "stewart/model/types.h"

namespace stewart {

/// `sensors`: the potentiometers and the IMU, as simulated and as expected.
struct SensorConfig {
  double rate_hz = 1000.0;
  double leg_pot_noise_std_m = 0.0;
  int leg_adc_bits = 10;  ///< quantisation over the stroke; 0 = none
  double gyro_noise_std_radps = 0.0;
  Vector3d gyro_bias_radps = Vector3d::Zero();
  double accel_noise_std_mps2 = 0.0;
  Vector3d accel_bias_mps2 = Vector3d::Zero();
  Vector3d imu_offset_in_P_m = Vector3d::Zero();  ///< IMU position in {P}
  bool has_orientation = false;
  double orientation_noise_std_rad = 0.0;
  unsigned seed = 0;
};

/// Leg-length step of the potentiometer ADC (m): codes 0 .. 2^bits - 1 span
/// the stroke, so stroke / (2^bits - 1); 0 when leg_adc_bits = 0 (no
/// quantisation). The simulator quantises with it, the estimator models it.
double LegAdcStepM(const SensorConfig& sensors, double stroke_m);

}  // namespace stewart
