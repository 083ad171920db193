#include "stewart/plant_sim/command_policy.h"

#include <algorithm>

#include "stewart/common/check.h"

namespace stewart {

std::string ForceCommandProblem(const Vector6d& force_n) {
  if (!force_n.allFinite()) return "non_finite_force";
  return "";
}

RealTimeCommandHold::RealTimeCommandHold(int64_t max_age_us) : max_age_us_(max_age_us) {
  STEWART_CHECK(max_age_us > 0, "RealTimeCommandHold: max_age_us must be positive");
}

void RealTimeCommandHold::OnCommand(const Vector6d& force_n, int64_t sample_utime, bool drive_off) {
  have_command_ = true;
  sample_utime_ = sample_utime;
  drive_off_ = drive_off;
  last_force_n_ = force_n;
}

RealTimeCommandHold::Decision RealTimeCommandHold::Decide(int64_t tick_sample_utime) const {
  Decision d;
  const int64_t age_us = tick_sample_utime - sample_utime_;
  d.timed_out = !have_command_ || age_us > max_age_us_;
  if (d.timed_out || drive_off_) {
    // Nothing young enough to apply, or the supervisor's drive off: the
    // motors are unpowered and the lead screws hold every leg.
    d.actuators_off = true;
    return d;
  }
  d.force_cmd_n = last_force_n_;
  d.age_us = age_us;
  return d;
}

LockstepMatch MatchLockstepCommand(int64_t awaited_sample_utime, int64_t command_sample_utime) {
  if (command_sample_utime == awaited_sample_utime) return LockstepMatch::kAnswer;
  return command_sample_utime < awaited_sample_utime ? LockstepMatch::kStale
                                                     : LockstepMatch::kFuture;
}

}  // namespace stewart
