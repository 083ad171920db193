#include "stewart/safety/safety_process.h"

#include <algorithm>
#include <cmath>

namespace stewart::safety {
namespace {

bool StateFinite(const StateSample& s) {
  return s.q.allFinite() && s.qd.allFinite() && s.disturbance.allFinite() &&
         s.disturbance_std.allFinite();
}

}  // namespace

SafetyProcess::SafetyProcess(const PlatformParams& platform, const SafetyConfig& safety,
                             const ActuatorConfig& actuators, const SupervisorConfig& supervisor,
                             ReferenceQpSolver* reference, HealthCounters* counters,
                             const TimePlausibilityParams& time)
    : filter_(platform, safety, actuators, reference),
      supervisor_(supervisor),
      counters_(counters),
      stale_age_us_(static_cast<int64_t>(safety.stale_age_s * 1e6)),
      time_check_(time, "state", safety.stale_age_s, counters) {
  STEWART_CHECK(counters_ != nullptr, "SafetyProcess needs its counters");
  counters_->SetCounter("fallback_commands", 0);
  counters_->SetCounter("active_steps", 0);
  counters_->SetCounter("infeasible", 0);
  counters_->SetCounter("hold_commands", 0);
  counters_->SetCounter("drive_off_commands", 0);
  counters_->SetState(health_state::kOk);
}

const StateSample* SafetyProcess::FindState(int64_t sample_utime) const {
  for (int k = 0; k < states_count_; ++k) {
    const int index = (states_next_ - 1 - k + kStateHistory) % kStateHistory;
    if (states_[static_cast<size_t>(index)].sample_utime == sample_utime) {
      return &states_[static_cast<size_t>(index)];
    }
  }
  return nullptr;
}

bool SafetyProcess::OnState(const StateSample& state, SafetyOutput* out,
                            std::optional<int64_t> receive_wall_us) {
  if (!HandleState(state, out, receive_wall_us)) return false;
  Remember(*out, state.utime, state.seq, receive_wall_us);
  return true;
}

bool SafetyProcess::OnNominal(const ForceCommand& nominal, SafetyOutput* out,
                              std::optional<int64_t> receive_wall_us) {
  if (!HandleNominal(nominal, out, receive_wall_us)) return false;
  // Every answer of a nominal is for a state of the history (FindState).
  const StateSample* state = FindState(out->command.sample_utime);
  if (state != nullptr) {
    Remember(*out, state->utime, state->seq, receive_wall_us);
  } else {
    resend_.Clear();
  }
  return true;
}

void SafetyProcess::Remember(const SafetyOutput& out, int64_t utime, int64_t seq,
                             std::optional<int64_t> receive_wall_us) {
  last_answer_ = out;
  resend_.Answered(utime, seq, receive_wall_us);
}

bool SafetyProcess::HandleState(const StateSample& state, SafetyOutput* out,
                                std::optional<int64_t> receive_wall_us) {
  counters_->CountIn();
  if (!StateFinite(state)) {
    counters_->Reject("nonfinite_state");
    return false;
  }
  // Before it can become the newest state: one far ahead would put every
  // real state after it out of order, and be answered with its own time.
  if (!time_check_.CheckSource(state.utime, state.sample_utime, receive_wall_us)) return false;
  // A resend of the state answered last: the same command again, the
  // filter, the watchdog and the supervisor not stepped twice.
  if (resend_.AnswerAgain(state.utime, state.seq, receive_wall_us)) {
    counters_->Count("resends_answered");
    counters_->CountOut();
    *out = last_answer_;
    return true;
  }
  if (state.utime <= newest_state_utime_) {
    counters_->Reject("state_time_not_increasing");
    time_check_.SourceRejected(state.utime, receive_wall_us);
    return false;
  }
  time_check_.SourceAccepted(state.utime, receive_wall_us);
  states_[static_cast<size_t>(states_next_)] = state;
  states_next_ = (states_next_ + 1) % kStateHistory;
  states_count_ = std::min(states_count_ + 1, kStateHistory);
  newest_state_utime_ = state.utime;
  counters_->SetStackTime(state.utime, state.sample_utime);

  // The watchdog: no nominal command derived from a recent enough state
  // means the controller is gone or late. Judged against state time, so a
  // replayed log behaves as it did live.
  const bool pending_for_this =
      has_pending_nominal_ && pending_nominal_.sample_utime == state.sample_utime;
  has_pending_nominal_ = has_pending_nominal_ && !pending_for_this &&
                         pending_nominal_.sample_utime > state.sample_utime;
  if (!StateUsable(state)) {
    // The controller answers usable states only: after this gap it gets
    // stale_age_s from the next usable state, as at start-up.
    first_usable_state_utime_ = -1;
    if (state.sample_utime <= last_published_sample_utime_) return false;
    *out = Fallback(state, kCommandInvalidInput);
    return true;
  }
  // Judged on the nominals derived from earlier samples only: whether this
  // sample's own nominal overtook the state (multicast order) must not change
  // the answer, so a log or an in-process run replays the same commands.
  // From the first usable state after unusable ones (start-up, an estimator
  // restart) the watchdog counts from that state: the controller gets
  // stale_age_s to answer it, however late its answer arrives relative to
  // the next states (else whether the answer beat the next state over
  // multicast would decide between filter and fallback).
  if (first_usable_state_utime_ < 0) first_usable_state_utime_ = state.utime;
  const int64_t newest_earlier_nominal = newest_nominal_sample_utime_;
  // The pending nominal's state has come: from now on it shows the
  // controller alive.
  if (pending_for_this) {
    newest_nominal_sample_utime_ = std::max(newest_nominal_sample_utime_, state.sample_utime);
  }
  if (state.utime - std::max(newest_earlier_nominal, first_usable_state_utime_) > stale_age_us_) {
    if (state.sample_utime <= last_published_sample_utime_) return false;
    *out = Fallback(state, kCommandStaleInput);
    if (pending_for_this) counters_->Reject("nominal_already_answered");
    return true;
  }
  if (pending_for_this) {
    *out = Filter(state, pending_nominal_);
    return true;
  }
  return false;
}

bool SafetyProcess::HandleNominal(const ForceCommand& nominal, SafetyOutput* out,
                                  std::optional<int64_t> receive_wall_us) {
  counters_->CountIn();
  // Before anything keeps it: a non-finite nominal held for its state would
  // displace the real one (its state answered with the invalid-input
  // fallback, the real nominal refused as answered already).
  if (!nominal.force_n.allFinite()) {
    counters_->Reject("nominal_non_finite");
    return false;
  }
  // Against the states' time: a nominal far ahead would otherwise hold the
  // watchdog off until the states caught up with it.
  if (!time_check_.CheckOther("nominal", nominal.utime, nominal.sample_utime, receive_wall_us)) {
    return false;
  }
  // A command that arrives, even one answered already by a fallback, shows
  // the controller is alive; one ahead of every state only once its state
  // arrives (OnState).
  if (nominal.sample_utime <= newest_state_utime_) {
    newest_nominal_sample_utime_ = std::max(newest_nominal_sample_utime_, nominal.sample_utime);
  }
  if (nominal.sample_utime <= last_published_sample_utime_) {
    counters_->Reject("nominal_already_answered");  // a fallback went out for it
    return false;
  }
  const StateSample* state = FindState(nominal.sample_utime);
  if (state == nullptr) {
    if (nominal.sample_utime > newest_state_utime_) {
      // Multicast from two senders is not ordered: on a loaded machine the
      // controller's answer can overtake the estimate it answers. Held until
      // that state arrives (OnState), never filtered against another state.
      pending_nominal_ = nominal;
      has_pending_nominal_ = true;
      counters_->Count("nominal_before_state");
      return false;
    }
    counters_->Reject("nominal_without_state");
    return false;
  }
  if (newest_state_utime_ - nominal.sample_utime > stale_age_us_) {
    counters_->Reject("stale_nominal");
    if (state->sample_utime <= last_published_sample_utime_) return false;
    *out = Fallback(*state, kCommandStaleInput);
    return true;
  }
  *out = Filter(*state, nominal);
  return true;
}

SafetyOutput SafetyProcess::Filter(const StateSample& state, const ForceCommand& nominal) {
  const GeneralizedDisturbance disturbance{state.disturbance, state.disturbance_std};
  const Vector6d f_safe =
      filter_.Step(state.q, state.qd, nominal.force_n, disturbance, &diagnostics_);
  if (diagnostics_.flags & kFlagInvalidInput) counters_->Reject("invalid_nominal");
  if (diagnostics_.flags & kFlagOutsideSafeSet) counters_->Count("outside_safe_set");
  if (diagnostics_.flags & kFlagNominalBounded) counters_->Count("nominal_bounded");
  if (diagnostics_.flags & kFlagPerBarrier) counters_->Count("per_barrier");
  return Supervise(state, f_safe, nominal.sample_utime, 0);
}

SafetyOutput SafetyProcess::Fallback(const StateSample& state, int32_t reason) {
  const Vector6d f = filter_.SafeStopCommand(
      state.q, state.qd, GeneralizedDisturbance{state.disturbance, state.disturbance_std},
      &diagnostics_);
  counters_->Count("fallback_commands");
  return Supervise(state, f, state.sample_utime, reason);
}

SafetyOutput SafetyProcess::Supervise(const StateSample& state, const Vector6d& force_n,
                                      int64_t sample_utime, int32_t fallback_reason) {
  const bool filtered = fallback_reason == 0;
  SupervisorStep step;
  step.utime = state.utime;
  step.sample_utime = state.sample_utime;
  step.state_usable = StateUsable(state);
  // Outside a position limit whose recovery barrier steers back in, with
  // every velocity inside its limit, arming is allowed: refused, a platform
  // resting in the joint tolerance's band of a limit could never move, and a
  // load above the screws' back-drive force moves it with the drive off.
  step.limits_allow_arming = filtered && (diagnostics_.flags & kFlagInvalidInput) == 0 &&
                             !diagnostics_.barriers.outside_unrecoverably;
  step.filtered = filtered;
  const SupervisorMode mode = supervisor_.OnStep(step);
  // The heartbeat says when the platform is not under the filtered command.
  counters_->SetState(filtered && !mode.drive_off() && mode.state != SupervisorState::kHold
                          ? health_state::kOk
                          : health_state::kDegraded);
  // Without a usable state every force is open loop (a restarted EKF's
  // first estimates, a diverged one): the actuators off lock the legs (the
  // lead screws hold; plant_sim and the emulator model it), which needs no
  // state. A safe stop computed from such a state pushed a held platform to
  // 0.06 m/s after a 2 s device stall (ProcessFaults.HwEmulatorStoppedAndKilled).
  if (mode.drive_off() || !step.state_usable) {
    counters_->Count("drive_off_commands");
    // Not a control law's output: flagged a fallback, as the safe stop is.
    return Emit(Vector6d::Zero(), sample_utime,
                kCommandDriveOff | kCommandFallback | fallback_reason, fallback_reason, mode);
  }
  if (!filtered) {
    // Already the safe stop (a fallback): HOLD, or a fault ARMING/ARMED just
    // turned into HOLD.
    if (mode.state == SupervisorState::kHold) counters_->Count("hold_commands");
    return Emit(force_n, sample_utime, diagnostics_.flags | fallback_reason, fallback_reason, mode);
  }
  if (mode.state == SupervisorState::kArmed) {
    return Emit(force_n, sample_utime, diagnostics_.flags, 0, mode);
  }
  const GeneralizedDisturbance disturbance{state.disturbance, state.disturbance_std};
  // ARMING starts from the drive-on hold: d was not observable while the
  // legs were held.
  const Vector6d hold =
      mode.state == SupervisorState::kHold
          ? filter_.SafeStopCommand(state.q, state.qd, disturbance, &hold_diagnostics_)
          : filter_.DriveOnCommand(state.q, state.qd, disturbance, &hold_diagnostics_);
  if (mode.state == SupervisorState::kHold) {
    counters_->Count("hold_commands");
    SafetyOutput out = Emit(hold, sample_utime, hold_diagnostics_.flags, 0, mode);
    out.diagnostics = &hold_diagnostics_;
    return out;
  }
  // ARMING: both ends satisfy the CBF conditions, linear in F, so the blend
  // does too.
  const Vector6d blended = (1.0 - mode.blend) * hold + mode.blend * force_n;
  return Emit(blended, sample_utime, diagnostics_.flags, 0, mode);
}

SafetyOutput SafetyProcess::Emit(const Vector6d& force_n, int64_t sample_utime, int32_t flags,
                                 int32_t fallback_reason, const SupervisorMode& mode) {
  last_published_sample_utime_ = sample_utime;
  SafetyOutput out;
  out.command.utime = sample_utime;
  out.command.seq = seq_++;
  out.command.sample_utime = sample_utime;
  out.command.force_n = force_n;
  out.command.flags = flags;
  out.fallback_reason = fallback_reason;
  out.mode = mode;
  out.diagnostics = &diagnostics_;
  counters_->CountOut();
  // For monitors that follow the run from the heartbeat alone.
  if (diagnostics_.flags & kFlagFilterActive) counters_->Count("active_steps");
  if (diagnostics_.infeasible) counters_->Count("infeasible");
  return out;
}

}  // namespace stewart::safety
