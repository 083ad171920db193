#pragma once
// Which force acts on the plant in each mode (docs/simulation.md, "Modes"),
// free of LCM so it is unit-testable. Times are stack times in microseconds.
#include <cstdint>
#include <string>

#include "stewart/model/types.h"

namespace stewart {

/// Why a received force command cannot be applied; "" when it can.
/// Checks finiteness only: the magnitude is the actuator's to saturate (and
/// the guard's to bound, guard/actuator_guard.h).
std::string ForceCommandProblem(const Vector6d& force_n);

/// Real-time mode: holds the newest accepted command while its sample is no
/// older than max_age against the sample of the tick at hand; after that (or
/// before the first command) the actuators are off and the lead screws hold
/// the legs. The age is stack time, the command's own sample against the
/// plant's newest, not when the command arrived: a command computed from an
/// old sample (a stack that fell behind, an estimator stopped for 0.5 s) is
/// never applied, however recently it came in.
class RealTimeCommandHold {
 public:
  /// max_age_us > 0 (checked).
  explicit RealTimeCommandHold(int64_t max_age_us);

  /// An accepted command; `drive_off`: FLAG_DRIVE_OFF, actuators off while
  /// it is the newest.
  void OnCommand(const Vector6d& force_n, int64_t sample_utime, bool drive_off);

  struct Decision {
    Vector6d force_cmd_n = Vector6d::Zero();
    bool actuators_off = false;
    bool timed_out = false;  ///< no command young enough: actuators off
    int64_t age_us = -1;     ///< age of the command applied (-1: none applied)
  };
  /// For the tick whose sample is `tick_sample_utime`: a command's age is
  /// the tick's sample time minus the command's. The simulator's own
  /// lateness (behind its schedule, catching up ticks) is not counted: a
  /// late simulator is not a late platform, and counting it turned the
  /// actuators off on a congested link (docs/operations.md, "Several hosts").
  Decision Decide(int64_t tick_sample_utime) const;

 private:
  int64_t max_age_us_;
  bool have_command_ = false;
  int64_t sample_utime_ = 0;
  bool drive_off_ = false;
  Vector6d last_force_n_ = Vector6d::Zero();
};

/// Lockstep mode: a command answers tick k iff its sample_utime equals the
/// utime of the sensor sample of tick k.
enum class LockstepMatch { kAnswer, kStale, kFuture };
LockstepMatch MatchLockstepCommand(int64_t awaited_sample_utime, int64_t command_sample_utime);

}  // namespace stewart
