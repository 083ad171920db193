#include "stewart/controller/controller.h"

#include <algorithm>

#include "stewart/model/kinematics.h"

namespace stewart {

Controller::Controller(const PlatformParams& platform, const ControllerConfig& gains,
                       const Vector6d& home_pose, std::optional<Scenario> scenario)
    : platform_(platform),
      gains_(gains),
      scenario_(std::move(scenario)),
      active_(Setpoint::HoldAt(home_pose)) {}

void Controller::ShareModelTerms(std::shared_ptr<SharedDynamicsTerms> shared) {
  shared_terms_ = AttachSharedTerms(platform_, std::move(shared));
}

SetpointStatus Controller::Check(const Setpoint& setpoint) const {
  if (!setpoint.AllFinite()) return SetpointStatus::kNonFinite;
  if (!PoseInWorkspace(platform_, setpoint.q_des)) return SetpointStatus::kOutsideWorkspace;
  return SetpointStatus::kAccepted;
}

SetpointStatus Controller::OfferSetpoint(const Setpoint& setpoint) {
  const SetpointStatus status = Check(setpoint);
  if (scenario_) return status;
  rejected_ = status != SetpointStatus::kAccepted;
  if (!rejected_) active_ = setpoint;
  return status;
}

void Controller::SetMotionClock(int64_t utime, int64_t motion_time_us, bool running) {
  if (!motion_clock_ && restart_at_first_clock_) motion_offset_us_ = motion_time_us;
  motion_clock_ = MotionClock{utime, motion_time_us, running};
}

StepStatus Controller::Step(int64_t utime, const Vector6d& q, const Vector6d& qd,
                            ControllerOutput* out) {
  return Step(utime, q, qd, Vector6d::Zero(), out);
}

StepStatus Controller::Step(int64_t utime, const Vector6d& q, const Vector6d& qd,
                            const Vector6d& disturbance_n, ControllerOutput* out) {
  if (!q.allFinite() || !qd.allFinite() || !disturbance_n.allFinite()) {
    return StepStatus::kNonFiniteState;
  }
  if (last_utime_ && utime <= *last_utime_) return StepStatus::kTimeNotIncreasing;
  last_utime_ = utime;
  if (!first_utime_) first_utime_ = utime;
  double t_s = 1e-6 * static_cast<double>(utime - *first_utime_);
  if (motion_clock_) {
    const MotionClock& m = *motion_clock_;
    const int64_t since_us = m.running ? std::max<int64_t>(utime - m.utime, 0) : 0;
    t_s = 1e-6 * static_cast<double>(
                     std::max<int64_t>(m.motion_time_us + since_us - motion_offset_us_, 0));
  }

  std::optional<SetpointStatus> scenario_rejection;
  if (scenario_) {
    const Setpoint sample = scenario_->Evaluate(t_s);
    const SetpointStatus status = Check(sample);
    rejected_ = status != SetpointStatus::kAccepted;
    if (rejected_) {
      scenario_rejection = status;
    } else {
      active_ = sample;
    }
    if (t_s >= scenario_->duration_s()) scenario_finished_ = true;
  }

  const Vector6d force_n = NominalForce(
      platform_, gains_, q, qd, gains_.compensate_disturbance ? disturbance_n : Vector6d::Zero(),
      active_, &terms_, shared_terms_.get());
  if (!force_n.allFinite()) return StepStatus::kNonFiniteForce;
  out->force_n = force_n;
  out->setpoint = active_;
  out->setpoint_rejected = rejected_;
  out->scenario_rejection = scenario_rejection;
  out->scenario_time_s = t_s;
  return StepStatus::kOk;
}

}  // namespace stewart
