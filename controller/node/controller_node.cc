#include "controller_node.h"

#include <spdlog/spdlog.h>

#include "stewart/node/eigen_msg.h"
#include "stewart/node/lcm_handle.h"
#include "stewart/node/node_loop.h"
#include "stewart/node/stop_signal.h"

namespace stewart {
namespace {

constexpr int kPollMs = 50;

Setpoint FromMessage(const setpoint_t& msg) {
  Setpoint s;
  s.q_des = FromArray(msg.q_des);
  s.qd_des = FromArray(msg.qd_des);
  s.qdd_des = FromArray(msg.qdd_des);
  return s;
}

}  // namespace

ControllerNode::ControllerNode(const StackConfig& config, lcm::LCM* lcm,
                               std::optional<Scenario> scenario, bool exit_at_end)
    : config_(config),
      lcm_(lcm),
      receiver_(config.lcm.url),
      controller_(config.platform, config.controller, config.home_pose, std::move(scenario)),
      health_("controller", config.lcm.channels.health, config.lcm.health_rate_hz),
      exit_at_end_(exit_at_end) {
  receiver_.Subscribe(config_.lcm.channels.state_estimate, &ControllerNode::OnState, this);
  // A scenario's setpoints are echoed on the setpoint channel: listening to
  // it as well would feed the controller its own output.
  if (!controller_.following_scenario()) {
    receiver_.Subscribe(config_.lcm.channels.setpoint, &ControllerNode::OnSetpoint, this);
  }
}

void ControllerNode::OnSetpoint(const lcm::ReceiveBuffer*, const std::string&,
                                const setpoint_t* msg) {
  health_.CountIn();
  const SetpointStatus status = controller_.OfferSetpoint(FromMessage(*msg));
  if (status != SetpointStatus::kAccepted) health_.Reject(ToString(status));
}

void ControllerNode::OnState(const lcm::ReceiveBuffer*, const std::string&, const state_t* msg) {
  health_.CountIn();
  if ((msg->status & state_t::STATUS_VALID) == 0 || (msg->status & state_t::STATUS_DIVERGED) != 0) {
    health_.Reject("state_not_valid", "status " + std::to_string(msg->status));
    return;
  }
  ControllerOutput out;
  const StepStatus status =
      controller_.Step(msg->utime, FromArray(msg->q), FromArray(msg->qd), &out);
  if (status != StepStatus::kOk) {
    health_.Reject(ToString(status));
    return;
  }
  if (out.scenario_rejection) health_.Reject(ToString(*out.scenario_rejection));

  command_.utime = msg->sample_utime;
  command_.seq = command_seq_++;
  command_.sample_utime = msg->sample_utime;
  ToArray(out.force_n, command_.force_n);
  command_.flags = out.setpoint_rejected ? force_command_t::FLAG_SETPOINT_REJECTED : 0;
  lcm_->publish(config_.lcm.channels.command_nominal, &command_);
  health_.CountOut();

  if (controller_.following_scenario()) {
    setpoint_echo_.utime = msg->sample_utime;
    setpoint_echo_.seq = setpoint_seq_++;
    setpoint_echo_.sample_utime = msg->sample_utime;
    ToArray(out.setpoint.q_des, setpoint_echo_.q_des);
    ToArray(out.setpoint.qd_des, setpoint_echo_.qd_des);
    ToArray(out.setpoint.qdd_des, setpoint_echo_.qdd_des);
    lcm_->publish(config_.lcm.channels.setpoint, &setpoint_echo_);
  }
  health_.SetStackTime(msg->utime, msg->sample_utime);
  health_.SetState(out.setpoint_rejected ? health_t::STATE_DEGRADED : health_t::STATE_OK);
}

ExitCode ControllerNode::Run() {
  const auto& ch = config_.lcm.channels;
  spdlog::info("controller: {} -> {}{} on {}", ch.state_estimate, ch.command_nominal,
               controller_.following_scenario() ? " + " + ch.setpoint
                                                : " (live setpoints on " + ch.setpoint + ")",
               config_.lcm.url);
  return RunNodeLoop("controller", lcm_, &receiver_, &health_, kPollMs, [this] {
    if (!exit_at_end_ || !controller_.scenario_finished()) return false;
    spdlog::info("controller: scenario '{}' finished", controller_.scenario()->name());
    return true;
  });
}

}  // namespace stewart
