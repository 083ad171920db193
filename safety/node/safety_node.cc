#include "safety_node.h"

#include "stewart/node/eigen_msg.h"
#include "stewart/node/node_loop.h"
#include "stewart/safety/diagnostics_lcm.h"

namespace stewart {
SafetyNode::SafetyNode(const StackConfig& config, lcm::LCM* lcm,
                       safety::ReferenceQpSolver* reference)
    : config_(config),
      lcm_(lcm),
      receiver_(config.lcm.url),
      filter_(config.platform, config.safety, config.actuators, reference),
      health_("safety", config.lcm.channels.health, config.lcm.health_rate_hz),
      stale_age_us_(static_cast<int64_t>(config.safety.stale_age_s * 1e6)) {
  receiver_.Subscribe(config.lcm.channels.state_estimate, &SafetyNode::OnState, this);
  receiver_.Subscribe(config.lcm.channels.command_nominal, &SafetyNode::OnNominal, this);
  health_.SetCounter("fallback_commands", 0);
  health_.SetCounter("active_steps", 0);
  health_.SetCounter("infeasible", 0);
  health_.SetState(health_t::STATE_OK);
}

const state_t* SafetyNode::FindState(int64_t sample_utime) const {
  for (int k = 0; k < states_count_; ++k) {
    const int index = (states_next_ - 1 - k + kStateHistory) % kStateHistory;
    if (states_[static_cast<size_t>(index)].sample_utime == sample_utime) {
      return &states_[static_cast<size_t>(index)];
    }
  }
  return nullptr;
}

void SafetyNode::OnState(const lcm::ReceiveBuffer*, const std::string&, const state_t* msg) {
  health_.CountIn();
  if (!AllFinite(msg->q) || !AllFinite(msg->qd)) {
    health_.Reject("nonfinite_state");
    return;
  }
  if (msg->utime <= newest_state_utime_) {
    health_.Reject("state_time_not_increasing");
    return;
  }
  states_[static_cast<size_t>(states_next_)] = *msg;
  states_next_ = (states_next_ + 1) % kStateHistory;
  states_count_ = std::min(states_count_ + 1, kStateHistory);
  newest_state_utime_ = msg->utime;
  health_.SetStackTime(msg->utime, msg->sample_utime);

  // The watchdog: no nominal command derived from a recent enough state
  // means the controller is gone or late. Judged against state time, so a
  // replayed log behaves as it did live.
  const bool invalid_state =
      (msg->status & state_t::STATUS_VALID) == 0 || (msg->status & state_t::STATUS_DIVERGED) != 0;
  const bool pending_for_this =
      has_pending_nominal_ && pending_nominal_.sample_utime == msg->sample_utime;
  has_pending_nominal_ = has_pending_nominal_ && !pending_for_this &&
                         pending_nominal_.sample_utime > msg->sample_utime;
  if (invalid_state) {
    PublishFallback(*msg, force_command_t::FLAG_INVALID_INPUT);
  } else if (pending_for_this) {
    FilterNominal(*msg, pending_nominal_);
  } else if (msg->utime - newest_nominal_sample_utime_ > stale_age_us_) {
    PublishFallback(*msg, force_command_t::FLAG_STALE_INPUT);
  }
}

void SafetyNode::OnNominal(const lcm::ReceiveBuffer*, const std::string&,
                           const force_command_t* msg) {
  health_.CountIn();
  // A command that arrives, even one answered already by a fallback, shows
  // the controller is alive.
  newest_nominal_sample_utime_ = std::max(newest_nominal_sample_utime_, msg->sample_utime);
  if (msg->sample_utime <= last_published_sample_utime_) {
    health_.Reject("nominal_already_answered");  // a fallback went out for it
    return;
  }
  const state_t* state = FindState(msg->sample_utime);
  if (state == nullptr) {
    if (msg->sample_utime > newest_state_utime_) {
      // Multicast from two senders is not ordered: on a loaded machine the
      // controller's answer can overtake the estimate it answers. Held until
      // that state arrives (OnState), never filtered against another state.
      pending_nominal_ = *msg;
      has_pending_nominal_ = true;
      health_.Count("nominal_before_state");
      return;
    }
    health_.Reject("nominal_without_state");
    return;
  }
  if (newest_state_utime_ - msg->sample_utime > stale_age_us_) {
    health_.Reject("stale_nominal");
    PublishFallback(*state, force_command_t::FLAG_STALE_INPUT);
    return;
  }
  FilterNominal(*state, *msg);
}

void SafetyNode::FilterNominal(const state_t& state, const force_command_t& nominal) {
  const Vector6d f_safe = filter_.Step(FromArray(state.q), FromArray(state.qd),
                                       FromArray(nominal.force_n), &diagnostics_);
  if (diagnostics_.flags & safety::kFlagInvalidInput) health_.Reject("invalid_nominal");
  Publish(state, nominal.sample_utime, f_safe, diagnostics_, 0);
}

void SafetyNode::PublishFallback(const state_t& state, int32_t reason_flag) {
  if (state.sample_utime <= last_published_sample_utime_) return;
  const Vector6d f =
      filter_.SafeStopCommand(FromArray(state.q), FromArray(state.qd), &diagnostics_);
  health_.Count("fallback_commands");
  Publish(state, state.sample_utime, f, diagnostics_, reason_flag);
}

void SafetyNode::Publish(const state_t& state, int64_t sample_utime, const Vector6d& force_n,
                         const safety::SafetyDiagnostics& diagnostics, int32_t extra_flags) {
  last_published_sample_utime_ = sample_utime;
  command_.utime = sample_utime;
  command_.seq = seq_;
  command_.sample_utime = sample_utime;
  ToArray(force_n, command_.force_n);
  command_.flags = diagnostics.flags | extra_flags;
  lcm_->publish(config_.lcm.channels.command_safe, &command_);

  safety::FillDiagnosticsMessage(filter_, diagnostics, &diagnostics_msg_);
  diagnostics_msg_.utime = sample_utime;
  diagnostics_msg_.seq = seq_;
  diagnostics_msg_.sample_utime = sample_utime;
  diagnostics_msg_.fallback_reason |= extra_flags;
  lcm_->publish(config_.lcm.channels.safety_diagnostics, &diagnostics_msg_);
  ++seq_;
  health_.CountOut();
  // For monitors that follow the run from the heartbeat alone.
  if (diagnostics.flags & safety::kFlagFilterActive) health_.Count("active_steps");
  if (diagnostics.infeasible) health_.Count("infeasible");
  (void)state;
}

ExitCode SafetyNode::Run() { return RunNodeLoop("safety", lcm_, &receiver_, &health_, 50); }

}  // namespace stewart
