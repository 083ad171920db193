#include "lcm_actuator_device.h"

#include <chrono>

#include "stewart/hw_bridge/bringup.h"
#include "stewart/identify/inertial_fit.h"
#include "stewart/node/eigen_msg.h"
#include "stewart/node/stop_signal.h"

namespace stewart::identify {

LcmActuatorDevice::LcmActuatorDevice(const StackConfig& config, lcm::LCM* lcm, double timeout_s)
    : lcm_(lcm),
      receiver_(config.lcm.url),
      duty_channel_(hw::BringupDutyChannel(config.lcm.channel_prefix, config.lcm.channel_suffix)),
      timeout_s_(timeout_s) {
  receiver_.Subscribe(config.lcm.channels.sensors, &LcmActuatorDevice::OnSensor, this);
  receiver_.Subscribe(
      hw::BringupAppliedChannel(config.lcm.channel_prefix, config.lcm.channel_suffix),
      &LcmActuatorDevice::OnApplied, this);
}

void LcmActuatorDevice::OnSensor(const lcm::ReceiveBuffer*, const std::string&,
                                 const sensor_t* msg) {
  ++sensors_;
  have_sensor_ = true;
  sensor_ = *msg;
}

void LcmActuatorDevice::OnApplied(const lcm::ReceiveBuffer*, const std::string&,
                                  const duty_command_t* msg) {
  ++echoes_;
  have_echo_ = true;
  echo_ = *msg;
  if (!have_sensor_ || sensor_.sample_utime != echo_.sample_utime) return;
  // The bridge publishes a sample's sensor_t, then its echo: the pair. A
  // newer pair replaces one not yet taken: the procedure answers the newest
  // sample, or its command would be stale on arrival (counted).
  if (ready_) ++skipped_;
  ActuatorSample s;
  s.utime = sensor_.sample_utime;
  s.leg_length_m = FromArray(sensor_.leg_length_m);
  s.valid = (sensor_.status & sensor_t::STATUS_LEG_FAULT) == 0;
  s.applied_duty = FromArray(echo_.duty);
  s.applied_since_utime = echo_.utime;
  s.device_guard_mask = static_cast<uint8_t>(echo_.guard_mask);
  ready_sample_ = s;
  ready_ = true;
  have_sensor_ = false;
}

ActuatorSample LcmActuatorDevice::NextSample() {
  using Clock = std::chrono::steady_clock;
  const auto deadline = Clock::now() + std::chrono::duration<double>(timeout_s_);
  while (!ready_) {
    // Interrupted (SIGINT, SIGTERM): the procedure sends zero duty and the
    // tool stops the processes it started.
    if (StopRequested()) throw IdentificationError("interrupted: zero duty sent");
    if (receiver_.HandleTimeout(5) < 0) throw IdentificationError("LCM receive error");
    if (ready_) break;
    if (Clock::now() > deadline) {
      throw IdentificationError(
          sensors_ == 0 ? "no sensor_t from hw_bridge within " + std::to_string(timeout_s_) +
                              " s: is it running (and the device connected)?"
          : echoes_ == 0
              ? "sensor samples arrive but no bring-up echo: hw_bridge is not in bring-up mode "
                "(hw_bridge --bringup)"
              : "the samples stopped for " + std::to_string(timeout_s_) + " s");
    }
  }
  ready_ = false;
  return ready_sample_;
}

void LcmActuatorDevice::SetDuty(int64_t sample_utime, const Vector6d& duty) {
  duty_command_t msg{};
  msg.utime = sample_utime;
  msg.seq = seq_++;
  msg.sample_utime = sample_utime;
  ToArray(duty, msg.duty);
  lcm_->publish(duty_channel_, &msg);
}

}  // namespace stewart::identify
