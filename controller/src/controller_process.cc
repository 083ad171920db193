#include "stewart/controller/controller_process.h"

#include <string>
#include <utility>

#include "stewart/common/check.h"

namespace stewart {

ControllerProcess::ControllerProcess(const PlatformParams& platform, const ControllerConfig& gains,
                                     const Vector6d& home_pose, std::optional<Scenario> scenario,
                                     HealthCounters* counters, const TimePlausibilityParams& time)
    : controller_(platform, gains, home_pose, std::move(scenario)),
      counters_(counters),
      time_check_(time, "state", gains.stale_age_s, counters) {
  STEWART_CHECK(counters_ != nullptr, "ControllerProcess needs its counters");
}

void ControllerProcess::OnSetpoint(const Setpoint& setpoint) {
  counters_->CountIn();
  const SetpointStatus status = controller_.OfferSetpoint(setpoint);
  if (status != SetpointStatus::kAccepted) counters_->Reject(ToString(status));
}

void ControllerProcess::OnSupervisor(int64_t utime, int64_t motion_time_us, bool running) {
  counters_->CountIn();
  controller_.SetMotionClock(utime, motion_time_us, running);
}

ControllerVerdict ControllerProcess::OnState(const StateSample& state, ControllerProcessOutput* out,
                                             std::optional<int64_t> receive_wall_us) {
  counters_->CountIn();
  // Before the control law: the scenario clock starts at the first state
  // and a state far ahead would put every later one out of order.
  if (!time_check_.CheckSource(state.utime, state.sample_utime, receive_wall_us)) {
    return ControllerVerdict::kTimeImplausible;
  }
  // A resend of the state answered last: the same answer, the control law
  // (and the scenario clock) not stepped twice.
  if (resend_.AnswerAgain(state.utime, state.seq, receive_wall_us)) {
    counters_->Count("resends_answered");
    counters_->CountOut();
    *out = last_answer_;
    return ControllerVerdict::kPublished;
  }
  if (!StateUsable(state)) {
    // A real state (the estimator initialising): its time is the stack's.
    time_check_.SourceAccepted(state.utime, receive_wall_us);
    counters_->Reject("state_not_valid", "status " + std::to_string(state.status));
    return ControllerVerdict::kStateNotUsable;
  }
  ControllerOutput step;
  const StepStatus status =
      controller_.Step(state.utime, state.q, state.qd, state.disturbance, &step);
  if (status == StepStatus::kTimeNotIncreasing) {
    time_check_.SourceRejected(state.utime, receive_wall_us);
  } else {
    time_check_.SourceAccepted(state.utime, receive_wall_us);
  }
  if (status != StepStatus::kOk) {
    counters_->Reject(ToString(status));
    return ControllerVerdict::kStepRejected;
  }
  if (step.scenario_rejection) counters_->Reject(ToString(*step.scenario_rejection));

  out->command.utime = state.sample_utime;
  out->command.seq = command_seq_++;
  out->command.sample_utime = state.sample_utime;
  out->command.force_n = step.force_n;
  out->command.flags = step.setpoint_rejected ? kCommandSetpointRejected : 0;
  counters_->CountOut();
  out->has_setpoint_echo = controller_.following_scenario();
  if (out->has_setpoint_echo) {
    out->setpoint_echo.utime = state.sample_utime;
    out->setpoint_echo.seq = setpoint_seq_++;
    out->setpoint_echo.sample_utime = state.sample_utime;
    out->setpoint_echo.setpoint = step.setpoint;
  }
  counters_->SetStackTime(state.utime, state.sample_utime);
  counters_->SetState(step.setpoint_rejected ? health_state::kDegraded : health_state::kOk);
  last_answer_ = *out;
  resend_.Answered(state.utime, state.seq, receive_wall_us);
  return ControllerVerdict::kPublished;
}

}  // namespace stewart
