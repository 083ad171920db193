#include "stewart/plant_sim/command_policy.h"

#include <stdexcept>

namespace stewart {

TimeoutFallback ParseTimeoutFallback(const std::string& name) {
  if (name == "off") return TimeoutFallback::kActuatorsOff;
  if (name == "hold_last") return TimeoutFallback::kHoldLast;
  throw std::invalid_argument("unknown timeout fallback '" + name + "' (off | hold_last)");
}

std::string ForceCommandProblem(const Vector6d& force_n) {
  if (!force_n.allFinite()) return "non_finite_force";
  return "";
}

RealTimeCommandHold::RealTimeCommandHold(double command_timeout_s, TimeoutFallback fallback)
    : timeout_s_(command_timeout_s), fallback_(fallback) {}

void RealTimeCommandHold::OnCommand(const Vector6d& force_n, double now_s) {
  have_command_ = true;
  last_command_s_ = now_s;
  last_force_n_ = force_n;
}

RealTimeCommandHold::Decision RealTimeCommandHold::Decide(double now_s) const {
  Decision d;
  d.timed_out = !have_command_ || now_s - last_command_s_ > timeout_s_;
  if (!d.timed_out) {
    d.force_cmd_n = last_force_n_;
    return d;
  }
  // Before the first command there is nothing to hold: the motors are unpowered.
  if (fallback_ == TimeoutFallback::kHoldLast && have_command_) {
    d.force_cmd_n = last_force_n_;
  } else {
    d.actuators_off = true;
  }
  return d;
}

LockstepMatch MatchLockstepCommand(int64_t awaited_sample_utime, int64_t command_sample_utime) {
  if (command_sample_utime == awaited_sample_utime) return LockstepMatch::kAnswer;
  return command_sample_utime < awaited_sample_utime ? LockstepMatch::kStale
                                                     : LockstepMatch::kFuture;
}

}  // namespace stewart
