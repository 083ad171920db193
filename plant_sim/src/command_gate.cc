#include "stewart/plant_sim/command_gate.h"

#include "stewart/plant_sim/command_policy.h"

namespace stewart {
namespace {

CommandGate::Decision Reject(std::string reason, std::string detail, bool timed) {
  CommandGate::Decision d;
  d.action = CommandGate::Action::kReject;
  d.reason = std::move(reason);
  d.detail = std::move(detail);
  d.timed = timed;
  return d;
}

CommandGate::Decision Accept(CommandGate::Action action) {
  CommandGate::Decision d;
  d.action = action;
  d.timed = true;
  return d;
}

}  // namespace

CommandGate::CommandGate(bool lockstep, const SafeCommandAcceptorLimits& limits)
    : lockstep_(lockstep), acceptor_(limits) {}

void CommandGate::OnSamplePublished(int64_t sample_utime) {
  newest_sample_utime_ = sample_utime;
  acceptor_.OnSamplePublished(sample_utime);
  answered_ = false;
}

CommandGate::Decision CommandGate::Check(const ForceCommand& c, bool authentic) {
  const CommandRejection trust = acceptor_.Check(c, authentic);
  if (trust != CommandRejection::kNone) {
    return Reject(ToString(trust),
                  "force_command_t seq " + std::to_string(c.seq) + ", session " +
                      std::to_string(c.session_id) + ", sample_utime " +
                      std::to_string(c.sample_utime) + " (following session " +
                      std::to_string(acceptor_.session_id()) + ", newest sample " +
                      std::to_string(newest_sample_utime_) + ")",
                  false);
  }
  // Strings only on the rejection paths: an accepted command allocates nothing.
  const auto utime = [&c] { return std::to_string(c.sample_utime); };
  const auto awaited = [this] { return std::to_string(newest_sample_utime_); };
  if (lockstep_) {
    switch (MatchLockstepCommand(newest_sample_utime_, c.sample_utime)) {
      case LockstepMatch::kAnswer:
        if (answered_) return Reject("duplicate_answer", "sample_utime " + utime(), true);
        answered_ = true;
        answer_ = c;
        return Accept(Action::kAnswer);
      case LockstepMatch::kStale:
        return Reject("stale_sample_utime", utime() + " < awaited " + awaited(), true);
      case LockstepMatch::kFuture:
        return Reject("future_sample_utime", utime() + " > awaited " + awaited(), true);
    }
  }
  if (c.sample_utime < last_applied_sample_utime_) return Reject("out_of_order", utime(), true);
  last_applied_sample_utime_ = c.sample_utime;
  return Accept(Action::kApply);
}

}  // namespace stewart
