#include <climits>
#include <cmath>

#include "stewart/config/sections.h"

namespace stewart {

SensorConfig ParseSensorConfig(const ConfigNode& sensors) {
  SensorConfig s;
  s.rate_hz = sensors.PositiveDouble("rate_hz");
  s.leg_pot_noise_std_m = sensors.NonNegativeDouble("leg_pot_noise_std_m");
  s.leg_adc_bits = sensors.IntInRange("leg_adc_bits", 0, 24, "must be 0 (no quantisation) to 24");
  s.gyro_noise_std_radps = sensors.NonNegativeDouble("gyro_noise_std_radps");
  s.gyro_bias_radps = sensors.Vec3("gyro_bias_radps");
  s.accel_noise_std_mps2 = sensors.NonNegativeDouble("accel_noise_std_mps2");
  s.accel_bias_mps2 = sensors.Vec3("accel_bias_mps2");
  s.imu_offset_in_P_m = sensors.Vec3("imu_offset_m");
  s.has_orientation = sensors.Bool("has_orientation");
  s.orientation_noise_std_rad = sensors.NonNegativeDouble("orientation_noise_std_rad");
  s.seed = static_cast<unsigned>(sensors.IntInRange("seed", 0, INT_MAX, "must not be negative"));
  return s;
}

}  // namespace stewart
