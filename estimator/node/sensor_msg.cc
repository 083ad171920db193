#include "sensor_msg.h"

#include <tuple>

#include "stewart/node/eigen_msg.h"

namespace stewart {
SensorSample SampleFromMessage(const sensor_t& msg) {
  SensorSample s;
  const auto fields = [](auto& x) {
    return std::tie(x.utime, x.seq, x.leg_length_m, x.gyro_radps, x.accel_mps2,
                    x.orientation_rpy_rad, x.has_orientation);
  };
  CopyFields(fields(msg), fields(s));
  s.legs_valid = (msg.status & sensor_t::STATUS_LEG_FAULT) == 0;
  s.imu_valid = (msg.status & sensor_t::STATUS_IMU_FAULT) == 0;
  s.previous_answer_applied = (msg.status & sensor_t::STATUS_ANSWER_APPLIED) != 0;
  s.drive_off =
      (msg.status & (sensor_t::STATUS_ACTUATORS_OFF | sensor_t::STATUS_DEVICE_WATCHDOG)) != 0;
  return s;
}

}  // namespace stewart
