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

state_t StateFromEstimate(const Estimate& estimate, int64_t seq) {
  state_t msg{};
  msg.utime = estimate.utime;
  msg.seq = seq;
  msg.sample_utime = estimate.utime;
  ToArray(estimate.q, msg.q);
  ToArray(estimate.qd, msg.qd);
  ToArray(estimate.q_std, msg.q_std);
  ToArray(estimate.qd_std, msg.qd_std);
  msg.status = estimate.initializing ? int32_t{state_t::STATUS_INITIALIZING}
                                     : int32_t{state_t::STATUS_VALID};
  if (estimate.diverged) msg.status |= state_t::STATUS_DIVERGED;
  return msg;
}

}  // namespace stewart
