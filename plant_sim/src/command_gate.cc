#include "stewart/plant_sim/command_gate.h"

#include "stewart/plant_sim/command_policy.h"

namespace stewart {
namespace {

CommandGate::Decision Reject(std::string reason, std::string detail) {
  CommandGate::Decision d;
  d.action = CommandGate::Action::kReject;
  d.reason = std::move(reason);
  d.detail = std::move(detail);
  d.timed = true;
  return d;
}

CommandGate::Decision Accept(CommandGate::Action action) {
  CommandGate::Decision d;
  d.action = action;
  d.timed = true;
  return d;
}

}  // namespace

void CommandGate::OnSamplePublished(int64_t sample_utime) {
  newest_sample_utime_ = sample_utime;
  answered_ = false;
}

CommandGate::Decision CommandGate::Check(const Vector6d& force_n, int64_t sample_utime,
                                         int64_t seq) {
  const std::string problem = ForceCommandProblem(force_n);
  if (!problem.empty()) {
    Decision d = Reject(problem, "force_command_t seq " + std::to_string(seq));
    d.timed = false;
    return d;
  }
  const std::string utime = std::to_string(sample_utime);
  const std::string awaited = std::to_string(newest_sample_utime_);
  if (lockstep_) {
    switch (MatchLockstepCommand(newest_sample_utime_, sample_utime)) {
      case LockstepMatch::kAnswer:
        if (answered_) return Reject("duplicate_answer", "sample_utime " + utime);
        answered_ = true;
        answer_force_n_ = force_n;
        return Accept(Action::kAnswer);
      case LockstepMatch::kStale:
        return Reject("stale_sample_utime", utime + " < awaited " + awaited);
      case LockstepMatch::kFuture:
        return Reject("future_sample_utime", utime + " > awaited " + awaited);
    }
  }
  if (sample_utime > newest_sample_utime_) return Reject("future_sample_utime", utime);
  if (sample_utime < last_applied_sample_utime_) return Reject("out_of_order", utime);
  last_applied_sample_utime_ = sample_utime;
  return Accept(Action::kApply);
}

}  // namespace stewart
