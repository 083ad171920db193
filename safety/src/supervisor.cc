#include "stewart/safety/supervisor.h"

#include <algorithm>
#include <cmath>

#include "stewart/common/check.h"

namespace stewart::safety {
namespace {

bool Moving(SupervisorState s) {
  return s == SupervisorState::kArming || s == SupervisorState::kArmed;
}

}  // namespace

Supervisor::Supervisor(const SupervisorConfig& config) : config_(config) {
  STEWART_CHECK(config_.arming_ramp_s >= 0.0, "supervisor.arming_ramp_s must be >= 0");
  STEWART_CHECK(config_.fallback_latch_s >= 0.0, "supervisor.fallback_latch_s must be >= 0");
  STEWART_CHECK(config_.hold_brake_s >= 0.0, "supervisor.hold_brake_s must be >= 0");
}

double Supervisor::blend() const { return blend_; }

void Supervisor::Enter(SupervisorState next, const std::string& reason) {
  if (next != state_) {
    ++transitions_;
    hold_since_utime_ = -1;  // a HOLD's brake starts at its first step
  }
  state_ = next;
  reason_ = reason;
  if (next == SupervisorState::kArming) {
    ramp_start_utime_ = -1;
    blend_ = 0.0;
  } else {
    blend_ = next == SupervisorState::kArmed ? 1.0 : 0.0;
  }
}

std::string Supervisor::ArmBlocker() const {
  if (!has_step_) return "no state estimate yet";
  if (!last_step_.state_usable) return "state estimate not usable (estimator not converged)";
  if (!last_step_.limits_allow_arming) {
    return "velocity outside its limits, or pose outside a limit nothing steers back from";
  }
  if (!last_step_.filtered) return "no fresh nominal command (controller)";
  return "";
}

SupervisorMode Supervisor::OnStep(const SupervisorStep& step) {
  const int64_t dt_us = last_utime_ >= 0 ? std::max<int64_t>(step.utime - last_utime_, 0) : 0;
  if (Moving(state_)) motion_time_us_ += dt_us;
  last_utime_ = std::max(last_utime_, step.utime);
  last_sample_utime_ = step.sample_utime;
  last_step_ = step;
  has_step_ = true;

  // While moving, steps without a filtered nominal command get the filter's
  // fallback; when they last, it is a fault: the platform stays stopped.
  if (step.filtered) {
    fallback_since_utime_ = -1;
  } else if (fallback_since_utime_ < 0) {
    fallback_since_utime_ = step.utime;
  }
  const bool fallback_lasted = !step.filtered && step.utime - fallback_since_utime_ >=
                                                     std::llround(config_.fallback_latch_s * 1e6);
  if (Moving(state_) && fallback_lasted) {
    fault_latched_ = true;
    Enter(SupervisorState::kHold, step.state_usable ? "fault: no fresh nominal command (controller)"
                                                    : "fault: state estimate not usable");
  }
  if (state_ == SupervisorState::kDisarmed && config_.auto_arm && !fault_latched_ &&
      ArmBlocker().empty()) {
    Enter(SupervisorState::kArming, "armed automatically (simulation)");
  }
  if (state_ == SupervisorState::kArming) {
    if (ramp_start_utime_ < 0) ramp_start_utime_ = step.utime;
    const double elapsed_s = static_cast<double>(step.utime - ramp_start_utime_) * 1e-6;
    blend_ =
        config_.arming_ramp_s > 0.0 ? std::clamp(elapsed_s / config_.arming_ramp_s, 0.0, 1.0) : 1.0;
    if (blend_ >= 1.0) Enter(SupervisorState::kArmed, reason_);
  }
  SupervisorMode mode{state_, blend_};
  if (state_ == SupervisorState::kHold) {
    if (hold_since_utime_ < 0) hold_since_utime_ = step.utime;
    mode.hold_locked = config_.hold_drive_off &&
                       step.utime - hold_since_utime_ >= std::llround(config_.hold_brake_s * 1e6);
  }
  return mode;
}

bool Supervisor::OnOperator(OperatorCommand command, bool processes_healthy,
                            const std::string& why_not, std::string* rejection) {
  const auto reject = [rejection](const std::string& why) {
    if (rejection != nullptr) *rejection = why;
    return false;
  };
  switch (command) {
    case OperatorCommand::kHeartbeat:
      return true;
    case OperatorCommand::kEstop:
      Enter(SupervisorState::kEstop, "operator estop");
      return true;
    case OperatorCommand::kHold:
      if (Moving(state_)) Enter(SupervisorState::kHold, "operator hold");
      if (state_ == SupervisorState::kHold) return true;
      return reject(std::string("hold: nothing moves in ") + ToString(state_));
    case OperatorCommand::kReset:
      fault_latched_ = false;
      if (state_ == SupervisorState::kEstop) {
        Enter(SupervisorState::kDisarmed, "reset after estop");
      } else if (state_ == SupervisorState::kHold) {
        reason_ = "fault acknowledged; resume to move";
      }
      return true;
    case OperatorCommand::kArm:
    case OperatorCommand::kResume: {
      const bool arm = command == OperatorCommand::kArm;
      const SupervisorState from = arm ? SupervisorState::kDisarmed : SupervisorState::kHold;
      if (state_ != from) {
        return reject(std::string(ToString(command)) + ": only from " + ToString(from) + ", not " +
                      ToString(state_));
      }
      if (fault_latched_)
        return reject(std::string(ToString(command)) + ": unacknowledged " + reason_ +
                      " (reset first)");
      if (!processes_healthy) return reject(std::string(ToString(command)) + ": " + why_not);
      const std::string blocker = ArmBlocker();
      if (!blocker.empty()) return reject(std::string(ToString(command)) + ": " + blocker);
      Enter(SupervisorState::kArming, arm ? "operator arm" : "operator resume");
      return true;
    }
  }
  return reject("unknown operator command");
}

void Supervisor::OnFault(const std::string& reason) {
  ++faults_received_;
  last_fault_received_ = reason;
  const bool first = !fault_latched_;
  fault_latched_ = true;
  if (Moving(state_)) {
    Enter(SupervisorState::kHold, "fault: " + reason);
  } else if (first && state_ != SupervisorState::kEstop) {
    reason_ = "fault: " + reason;
  }
}

std::string Supervisor::InputWaitFault(int64_t waited_us) const {
  const double allowed_s = std::max(config_.fallback_latch_s, kMinInputWait_s);
  if (!config_.stall_check || !Moving(state_) || waited_us <= std::llround(allowed_s * 1e6)) {
    return "";
  }
  return "safety process stalled: a state waited " + std::to_string(waited_us / 1000) +
         " ms to be read (allowed: " + std::to_string(allowed_s) + " s)";
}

}  // namespace stewart::safety
