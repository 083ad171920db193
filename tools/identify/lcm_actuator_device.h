#pragma once
// The actuator procedure's device over LCM: hw_bridge in bring-up mode
// (hw_bridge --bringup). Samples are sensor_t on channels.sensors paired
// with the bridge's echo (duty_command_t on <prefix>BRINGUP_DUTY_APPLIED)
// of the same sample; duties go out as duty_command_t on
// <prefix>BRINGUP_DUTY (docs/messages.md).
#include <lcm/lcm-cpp.hpp>
#include <memory>
#include <string>

#include "stewart/config/stack_config.h"
#include "stewart/duty_command_t.hpp"
#include "stewart/identify/actuator_device.h"
#include "stewart/node/lcm_receiver.h"
#include "stewart/sensor_t.hpp"

namespace stewart::identify {

class LcmActuatorDevice final : public ActuatorDevice {
 public:
  /// `timeout_s`: no sample for this long (wall clock) ends the run with
  /// IdentificationError naming what is missing.
  LcmActuatorDevice(const StackConfig& config, lcm::LCM* lcm, double timeout_s);

  ActuatorSample NextSample() override;
  void SetDuty(int64_t sample_utime, const Vector6d& duty) override;

  long sensor_messages() const { return sensors_; }
  long echo_messages() const { return echoes_; }
  /// Samples replaced by a newer one before the procedure took them.
  long skipped_samples() const { return skipped_; }

 private:
  void OnSensor(const lcm::ReceiveBuffer*, const std::string&, const sensor_t* msg);
  void OnApplied(const lcm::ReceiveBuffer*, const std::string&, const duty_command_t* msg);

  lcm::LCM* lcm_;
  LcmReceiver receiver_;
  std::string duty_channel_;
  double timeout_s_;
  // The newest sensor sample not yet paired with its echo, and the newest
  // echo; a sample is complete when both carry the same sample_utime.
  bool have_sensor_ = false;
  sensor_t sensor_{};
  bool have_echo_ = false;
  duty_command_t echo_{};
  bool ready_ = false;
  ActuatorSample ready_sample_;
  int64_t seq_ = 0;
  long sensors_ = 0;
  long echoes_ = 0;
  long skipped_ = 0;
};

}  // namespace stewart::identify
