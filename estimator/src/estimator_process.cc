#include "stewart/estimator/estimator_process.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <tuple>

#include "stewart/common/check.h"
#include "stewart/guard/actuator_guard.h"

namespace stewart {

StateSample StateFromEstimate(const Estimate& estimate, int64_t seq) {
  StateSample s;
  s.utime = s.sample_utime = estimate.utime;
  s.seq = seq;
  std::tie(s.q, s.qd, s.q_std, s.qd_std, s.disturbance, s.disturbance_std) =
      std::tie(estimate.q, estimate.qd, estimate.q_std, estimate.qd_std, estimate.disturbance_n,
               estimate.disturbance_std_n);
  s.status = estimate.initializing ? kStateInitializing : kStateValid;
  if (estimate.diverged) s.status |= kStateDiverged;
  return s;
}

EstimatorProcess::EstimatorProcess(const PlatformParams& platform, const ActuatorConfig& actuators,
                                   const SensorConfig& sensors, const EstimatorConfig& estimator,
                                   const Vector6d& home_pose, HealthCounters* counters,
                                   const TimePlausibilityParams& time,
                                   std::optional<SafeCommandAcceptorLimits> trust,
                                   double guard_force_limit_n)
    : ekf_(platform, actuators, sensors, estimator, home_pose),
      counters_(counters),
      time_check_(time, estimator.perfect_state ? "truth" : "sensor", estimator.max_dt_s, counters),
      guard_force_limit_n_(guard_force_limit_n) {
  if (trust) acceptor_.emplace(*trust);
  STEWART_CHECK(counters_ != nullptr, "EstimatorProcess needs its counters");
  STEWART_CHECK(guard_force_limit_n_ > 0.0, "guard_force_limit_n must be positive");
}

AnnouncementVerdict EstimatorProcess::OnAnnouncement(const SessionAnnouncement& announcement,
                                                     bool authentic, int64_t wall_us) {
  if (!acceptor_) return AnnouncementVerdict::kAdopted;
  counters_->CountIn();
  const AnnouncementVerdict verdict = acceptor_->OnAnnouncement(announcement, authentic, wall_us);
  if (IsRejection(verdict)) counters_->Reject(ToString(verdict));
  return verdict;
}

bool EstimatorProcess::OnCommand(const ForceCommand& command, StateSample* out,
                                 std::optional<int64_t> receive_wall_us, bool authentic) {
  counters_->CountIn();
  // A command's sample_utime is the sample it answers: the EKF files it
  // under that time, so a far-off one would act on every later prediction.
  if (!time_check_.CheckOther("command", command.utime, command.sample_utime, receive_wall_us)) {
    return false;
  }
  // The answer has come, whatever the verdict below: a sample waiting for
  // it waits no longer (an answer the actuators refuse is not what they
  // applied either).
  newest_answer_utime_ = std::max(newest_answer_utime_, command.sample_utime);
  if (!command.force_n.allFinite()) {
    counters_->Reject("command_non_finite");
  } else if (const CommandRejection rejection =
                 acceptor_ ? acceptor_->Check(command, authentic) : CommandRejection::kNone;
             rejection != CommandRejection::kNone) {
    counters_->Reject(ToString(rejection));
  } else if ((command.flags & kCommandDriveOff) == 0 &&
             AnyForceBeyondGuardBound(command.force_n, guard_force_limit_n_)) {
    // The actuators' guard trips on it and turns the drive off.
    counters_->Reject("command_beyond_guard_force");
    ekf_.SetForceCommand(command.sample_utime, Vector6d::Zero(), /*drive_off=*/true);
  } else {
    ekf_.SetForceCommand(command.sample_utime, command.force_n,
                         (command.flags & kCommandDriveOff) != 0);
  }
  if (waiting_ && newest_answer_utime_ >= waiting_->answer_utime) return ReleaseWaiting(out);
  return false;
}

bool EstimatorProcess::OnSensor(const SensorSample& sample, StateSample* out,
                                std::optional<int64_t> receive_wall_us) {
  counters_->CountIn();
  // Before the EKF: a sample far ahead would restart it at that time (a gap
  // over max_dt_s) and every real sample after it would be out of order.
  if (!time_check_.CheckSource(sample.utime, sample.utime, receive_wall_us)) return false;
  // A resend of the sample answered last: the same estimate again, the EKF
  // untouched (it must not step twice on one sample).
  if (resend_.AnswerAgain(sample.utime, sample.seq, receive_wall_us)) {
    counters_->Count("resends_answered");
    counters_->CountOut();
    *out = last_answer_;
    return true;
  }
  if (waiting_) {
    if (sample.utime == waiting_->sample.utime) return false;  // resent: it still waits
    // A newer sample: the waiting one's answer did not come. It updates the
    // EKF; the newer one's estimate supersedes its own.
    counters_->Count("answer_not_heard");
    StateSample superseded;
    ReleaseWaiting(&superseded);
  }
  if (sample.previous_answer_applied && last_sample_utime_ >= 0 &&
      sample.utime > last_sample_utime_ && newest_answer_utime_ < last_sample_utime_) {
    waiting_ = WaitingSample{sample, receive_wall_us, last_sample_utime_};
    counters_->Count("samples_waited_for_answer");
    return false;
  }
  return Update(sample, out, receive_wall_us);
}

bool EstimatorProcess::FlushWaiting(int64_t wall_us, StateSample* out) {
  if (!waiting_ || !waiting_->receive_wall_us) return false;
  if (wall_us - *waiting_->receive_wall_us < std::llround(kAnswerWait_s * 1e6)) return false;
  counters_->Count("answer_not_heard");
  return ReleaseWaiting(out);
}

bool EstimatorProcess::ReleaseWaiting(StateSample* out) {
  const WaitingSample w = *waiting_;
  waiting_.reset();
  return Update(w.sample, out, w.receive_wall_us);
}

bool EstimatorProcess::Update(const SensorSample& sample, StateSample* out,
                              std::optional<int64_t> receive_wall_us) {
  last_sample_utime_ = std::max(last_sample_utime_, sample.utime);
  // The acceptor judges a command's age against the newest sample, as the
  // plant judges it against the newest it published.
  if (acceptor_ && sample.utime >= acceptor_->newest_sample_utime()) {
    acceptor_->OnSamplePublished(sample.utime);
  }
  const UpdateResult result = ekf_.Update(sample);
  last_update_events_ = result.events;
  if (result.Has(kRejectTime)) {
    time_check_.SourceRejected(sample.utime, receive_wall_us);
  } else {
    time_check_.SourceAccepted(sample.utime, receive_wall_us);
  }
  for (uint32_t bit = 1; bit <= kEventLast; bit <<= 1) {
    if (!(result.events & bit)) continue;
    const auto event = static_cast<EkfEvent>(bit);
    if (IsRejection(event)) {
      counters_->Reject(EkfEventName(event));
    } else {
      counters_->Count(EkfEventName(event));
    }
  }
  if (result.Has(kEventDiverged)) {
    spdlog::warn("estimator: divergence detected at utime {}: restarted from the legs",
                 sample.utime);
  }
  if (!result.has_estimate) return false;
  const Estimate& estimate = ekf_.estimate();
  counters_->SetState(estimate.diverged ? health_state::kDegraded : health_state::kOk);
  counters_->SetStackTime(sample.utime, sample.utime);
  if (!Emit(StateFromEstimate(estimate, seq_), out)) {
    resend_.Clear();
    return false;
  }
  last_answer_ = *out;
  resend_.Answered(sample.utime, sample.seq, receive_wall_us);
  return true;
}

bool EstimatorProcess::OnTruth(const StateSample& truth, StateSample* out,
                               std::optional<int64_t> receive_wall_us) {
  counters_->CountIn();
  if (!time_check_.CheckSource(truth.utime, truth.sample_utime, receive_wall_us)) return false;
  if (!truth.q.allFinite() || !truth.qd.allFinite()) {
    counters_->Reject("truth_non_finite");
    return false;
  }
  time_check_.SourceAccepted(truth.utime, receive_wall_us);
  StateSample state = truth;
  state.seq = seq_;
  state.status = kStateValid | kStatePerfectState;
  counters_->SetState(health_state::kDegraded);  // perfect state is never a real estimate
  counters_->SetError("perfect_state mode");
  counters_->SetStackTime(truth.utime, truth.sample_utime);
  return Emit(state, out);
}

bool EstimatorProcess::Emit(const StateSample& state, StateSample* out) {
  if (!state.q.allFinite() || !state.qd.allFinite() || !state.q_std.allFinite() ||
      !state.qd_std.allFinite() || !state.disturbance.allFinite() ||
      !state.disturbance_std.allFinite()) {
    counters_->Reject("estimate_non_finite");
    return false;
  }
  *out = state;
  ++seq_;
  counters_->CountOut();
  return true;
}

}  // namespace stewart
