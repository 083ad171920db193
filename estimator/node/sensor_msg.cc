#include "sensor_msg.h"

#include "stewart/node/eigen_msg.h"

namespace stewart {
SensorSample SampleFromMessage(const sensor_t& msg) {
  SensorSample s;
  s.utime = msg.utime;
  s.leg_length_m = FromArray(msg.leg_length_m);
  s.gyro_radps = FromArray(msg.gyro_radps);
  s.accel_mps2 = FromArray(msg.accel_mps2);
  s.orientation_rpy_rad = FromArray(msg.orientation_rpy_rad);
  s.has_orientation = msg.has_orientation;
  s.legs_valid = (msg.status & sensor_t::STATUS_LEG_FAULT) == 0;
  s.imu_valid = (msg.status & sensor_t::STATUS_IMU_FAULT) == 0;
  return s;
}

}  // namespace stewart
