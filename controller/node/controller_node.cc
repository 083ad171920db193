#include "controller_node.h"

#include <spdlog/spdlog.h>

#include "stewart/node/eigen_msg.h"
#include "stewart/node/lcm_handle.h"
#include "stewart/node/node_loop.h"
#include "stewart/node/signal_messages.h"
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
                               std::optional<Scenario> scenario, bool exit_at_end,
                               bool restart_scenario)
    : config_(config),
      lcm_(lcm),
      receiver_(config.lcm.url),
      health_("controller", config.lcm.channels.health, config.lcm.health_rate_hz),
      process_(config.platform, config.controller, config.home_pose, std::move(scenario), &health_,
               config.lcm.time_plausibility),
      auth_(MessageAuthenticator::FromKeyFile(config.lcm.auth_key_file)),
      exit_at_end_(exit_at_end) {
  if (restart_scenario) process_.RestartScenario();
  receiver_.Subscribe(config_.lcm.channels.state_estimate, &ControllerNode::OnState, this);
  receiver_.Subscribe(config_.lcm.channels.supervisor, &ControllerNode::OnSupervisor, this);
  // A scenario's setpoints are echoed on the setpoint channel: listening to
  // it as well would feed the controller its own output.
  if (!process_.controller().following_scenario()) {
    receiver_.Subscribe(config_.lcm.channels.setpoint, &ControllerNode::OnSetpoint, this);
  }
}

void ControllerNode::OnSetpoint(const lcm::ReceiveBuffer*, const std::string&,
                                const setpoint_t* msg) {
  process_.OnSetpoint(FromMessage(*msg));
}

void ControllerNode::OnSupervisor(const lcm::ReceiveBuffer*, const std::string&,
                                  const supervisor_state_t* msg) {
  if (!auth_.Verify(*msg)) {
    health_.Reject("supervisor_bad_mac");
    return;
  }
  const bool running = msg->state == supervisor_state_t::STATE_ARMING ||
                       msg->state == supervisor_state_t::STATE_ARMED;
  process_.OnSupervisor(msg->utime, msg->motion_time_us, running);
}

void ControllerNode::OnState(const lcm::ReceiveBuffer* rbuf, const std::string&,
                             const state_t* msg) {
  ControllerProcessOutput out;
  if (process_.OnState(FromMessage(*msg), &out, rbuf->recv_utime) !=
      ControllerVerdict::kPublished) {
    return;
  }
  ToMessage(out.command, &command_);
  lcm_->publish(config_.lcm.channels.command_nominal, &command_);
  if (out.has_setpoint_echo) {
    const SetpointEcho& echo = out.setpoint_echo;
    setpoint_echo_.utime = echo.utime;
    setpoint_echo_.seq = echo.seq;
    setpoint_echo_.sample_utime = echo.sample_utime;
    ToArray(echo.setpoint.q_des, setpoint_echo_.q_des);
    ToArray(echo.setpoint.qd_des, setpoint_echo_.qd_des);
    ToArray(echo.setpoint.qdd_des, setpoint_echo_.qdd_des);
    lcm_->publish(config_.lcm.channels.setpoint, &setpoint_echo_);
  }
}

ExitCode ControllerNode::Run() {
  const auto& ch = config_.lcm.channels;
  spdlog::info("controller: {} -> {}{} on {}", ch.state_estimate, ch.command_nominal,
               process_.controller().following_scenario()
                   ? " + " + ch.setpoint
                   : " (live setpoints on " + ch.setpoint + ")",
               config_.lcm.url);
  return RunNodeLoop("controller", lcm_, &receiver_, &health_, kPollMs, [this] {
    if (!exit_at_end_ || !process_.controller().scenario_finished()) return false;
    spdlog::info("controller: scenario '{}' finished", process_.controller().scenario()->name());
    return true;
  });
}

}  // namespace stewart
