#include "safety_node.h"

#include "stewart/node/node_loop.h"
#include "stewart/node/signal_messages.h"
#include "stewart/safety/diagnostics_lcm.h"

namespace stewart {

SafetyNode::SafetyNode(const StackConfig& config, lcm::LCM* lcm,
                       safety::ReferenceQpSolver* reference)
    : config_(config),
      lcm_(lcm),
      receiver_(config.lcm.url),
      health_("safety", config.lcm.channels.health, config.lcm.health_rate_hz),
      process_(config.platform, config.safety, config.actuators, reference, &health_,
               config.lcm.time_plausibility) {
  receiver_.Subscribe(config.lcm.channels.state_estimate, &SafetyNode::OnState, this);
  receiver_.Subscribe(config.lcm.channels.command_nominal, &SafetyNode::OnNominal, this);
}

void SafetyNode::OnState(const lcm::ReceiveBuffer* rbuf, const std::string&, const state_t* msg) {
  safety::SafetyOutput out;
  if (process_.OnState(FromMessage(*msg), &out, rbuf->recv_utime)) Publish(out);
}

void SafetyNode::OnNominal(const lcm::ReceiveBuffer* rbuf, const std::string&,
                           const force_command_t* msg) {
  safety::SafetyOutput out;
  if (process_.OnNominal(FromMessage(*msg), &out, rbuf->recv_utime)) Publish(out);
}

void SafetyNode::Publish(const safety::SafetyOutput& out) {
  ToMessage(out.command, &command_);
  lcm_->publish(config_.lcm.channels.command_safe, &command_);
  safety::FillDiagnosticsMessage(process_.filter(), out, &diagnostics_msg_);
  lcm_->publish(config_.lcm.channels.safety_diagnostics, &diagnostics_msg_);
}

ExitCode SafetyNode::Run() { return RunNodeLoop("safety", lcm_, &receiver_, &health_, 50); }

}  // namespace stewart
