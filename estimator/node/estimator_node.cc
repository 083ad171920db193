#include "estimator_node.h"

#include <spdlog/spdlog.h>

#include "sensor_msg.h"
#include "stewart/guard/guard_limits.h"
#include "stewart/node/node_loop.h"
#include "stewart/node/signal_messages.h"

namespace stewart {

EstimatorNode::EstimatorNode(const StackConfig& config, lcm::LCM* lcm, bool perfect_state)
    : config_(config),
      lcm_(lcm),
      receiver_(config.lcm.url),
      health_("estimator", config.lcm.channels.health, config.lcm.health_rate_hz),
      auth_(MessageAuthenticator::FromKeyFile(config.lcm.auth_key_file)),
      process_(config.platform, config.actuators, config.sensors, config.estimator,
               config.home_pose, &health_, config.lcm.time_plausibility,
               AcceptorLimitsOf(config.guard, config.estimator.command_timeout_s),
               config.guard.leg_force_limit_n) {
  if (perfect_state) {
    spdlog::warn("estimator: PERFECT STATE mode: republishing {} as {} (testing only)",
                 config_.lcm.channels.state_truth, config_.lcm.channels.state_estimate);
    receiver_.Subscribe(config_.lcm.channels.state_truth, &EstimatorNode::OnTruth, this);
  } else {
    receiver_.Subscribe(config_.lcm.channels.sensors, &EstimatorNode::OnSensor, this);
    receiver_.Subscribe(config_.lcm.channels.command_safe, &EstimatorNode::OnCommand, this);
    receiver_.Subscribe(config_.lcm.channels.supervisor, &EstimatorNode::OnSupervisor, this);
  }
}

void EstimatorNode::OnSupervisor(const lcm::ReceiveBuffer* rbuf, const std::string&,
                                 const supervisor_state_t* msg) {
  const AnnouncementVerdict v =
      process_.OnAnnouncement(SessionAnnouncement{msg->utime, msg->seq, msg->session_id},
                              auth_.Verify(*msg), rbuf->recv_utime);
  if (v == AnnouncementVerdict::kAdopted) {
    spdlog::info("estimator: believing safety session {} (announced at utime {})", msg->session_id,
                 msg->utime);
  }
}

void EstimatorNode::OnCommand(const lcm::ReceiveBuffer* rbuf, const std::string&,
                              const force_command_t* msg) {
  StateSample state;
  if (process_.OnCommand(FromMessage(*msg), &state, rbuf->recv_utime, auth_.Verify(*msg))) {
    Publish(state);
  }
}

void EstimatorNode::OnSensor(const lcm::ReceiveBuffer* rbuf, const std::string&,
                             const sensor_t* msg) {
  StateSample state;
  if (process_.OnSensor(SampleFromMessage(*msg), &state, rbuf->recv_utime)) Publish(state);
  health_.MaybePublish(lcm_);
}

void EstimatorNode::OnTruth(const lcm::ReceiveBuffer* rbuf, const std::string&,
                            const state_t* msg) {
  StateSample state;
  if (process_.OnTruth(FromMessage(*msg), &state, rbuf->recv_utime)) Publish(state);
  health_.MaybePublish(lcm_);
}

void EstimatorNode::Publish(const StateSample& state) {
  ToMessage(state, &state_msg_);
  if (loss_.Drops(config_.lcm.channels.state_estimate, state_msg_.seq)) return;
  lcm_->publish(config_.lcm.channels.state_estimate, &state_msg_);
}

ExitCode EstimatorNode::Run() {
  // A sample waiting for its answer (EstimatorProcess::OnSensor) is checked
  // every few ms, on the receive clock (SO_TIMESTAMP: the wall clock).
  // What the socket holds is read first: a process that was not scheduled
  // for a while may have its answer queued already.
  return RunNodeLoop("estimator", lcm_, &receiver_, &health_, 5, [this] {
    if (!process_.waiting()) return false;
    receiver_.HandleTimeout(0);
    StateSample state;
    if (process_.FlushWaiting(ReceiveClockUs(), &state)) Publish(state);
    return false;
  });
}

}  // namespace stewart
