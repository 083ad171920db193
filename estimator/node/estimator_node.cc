#include "estimator_node.h"

#include <spdlog/spdlog.h>

#include "sensor_msg.h"
#include "stewart/node/eigen_msg.h"
#include "stewart/node/node_loop.h"
#include "stewart/node/stop_signal.h"

namespace stewart {
EstimatorNode::EstimatorNode(const StackConfig& config, lcm::LCM* lcm, bool perfect_state)
    : config_(config),
      lcm_(lcm),
      receiver_(config.lcm.url),
      perfect_state_(perfect_state),
      ekf_(config.platform, config.actuators, config.sensors, config.estimator, config.home_pose),
      health_("estimator", config.lcm.channels.health, config.lcm.health_rate_hz) {
  if (perfect_state_) {
    spdlog::warn("estimator: PERFECT STATE mode: republishing {} as {} (testing only)",
                 config_.lcm.channels.state_truth, config_.lcm.channels.state_estimate);
    receiver_.Subscribe(config_.lcm.channels.state_truth, &EstimatorNode::OnTruth, this);
  } else {
    receiver_.Subscribe(config_.lcm.channels.sensors, &EstimatorNode::OnSensor, this);
    receiver_.Subscribe(config_.lcm.channels.command_safe, &EstimatorNode::OnCommand, this);
  }
}

void EstimatorNode::OnCommand(const lcm::ReceiveBuffer*, const std::string&,
                              const force_command_t* msg) {
  health_.CountIn();
  if (!AllFinite(msg->force_n)) {
    health_.Reject("command_non_finite");
    return;
  }
  ekf_.SetForceCommand(msg->sample_utime, FromArray(msg->force_n));
}

void EstimatorNode::OnSensor(const lcm::ReceiveBuffer*, const std::string&, const sensor_t* msg) {
  health_.CountIn();
  const UpdateResult result = ekf_.Update(SampleFromMessage(*msg));
  for (uint32_t bit = 1; bit <= kEventLast; bit <<= 1) {
    if (!(result.events & bit)) continue;
    const auto event = static_cast<EkfEvent>(bit);
    if (IsRejection(event)) {
      health_.Reject(EkfEventName(event));
    } else {
      health_.Count(EkfEventName(event));
    }
  }
  if (result.Has(kEventDiverged)) {
    spdlog::warn("estimator: divergence detected at utime {}: restarted from the legs", msg->utime);
  }
  if (!result.has_estimate) {
    health_.MaybePublish(lcm_);
    return;
  }
  const Estimate estimate = ekf_.estimate();
  const state_t state = StateFromEstimate(estimate, seq_);
  health_.SetState(estimate.diverged ? health_t::STATE_DEGRADED : health_t::STATE_OK);
  health_.SetStackTime(msg->utime, msg->utime);
  Publish(state);
}

void EstimatorNode::OnTruth(const lcm::ReceiveBuffer*, const std::string&, const state_t* msg) {
  health_.CountIn();
  if (!AllFinite(msg->q) || !AllFinite(msg->qd)) {
    health_.Reject("truth_non_finite");
    return;
  }
  state_t state = *msg;
  state.seq = seq_;
  state.status = state_t::STATUS_VALID | state_t::STATUS_PERFECT_STATE;
  health_.SetState(health_t::STATE_DEGRADED);  // perfect state is never a real estimate
  health_.SetError("perfect_state mode");
  health_.SetStackTime(msg->utime, msg->sample_utime);
  Publish(state);
}

void EstimatorNode::Publish(const state_t& msg) {
  if (!AllFinite(msg.q) || !AllFinite(msg.qd) || !AllFinite(msg.q_std) || !AllFinite(msg.qd_std)) {
    health_.Reject("estimate_non_finite");
    return;
  }
  lcm_->publish(config_.lcm.channels.state_estimate, &msg);
  ++seq_;
  health_.CountOut();
  health_.MaybePublish(lcm_);
}

ExitCode EstimatorNode::Run() { return RunNodeLoop("estimator", lcm_, &receiver_, &health_, 100); }

}  // namespace stewart
