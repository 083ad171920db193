#pragma once
// Which force acts on the plant in each mode (docs/simulation.md, "Modes"),
// free of LCM so it is unit-testable. Times are stack times in seconds.
#include <cstdint>
#include <string>

#include "stewart/model/types.h"

namespace stewart {

enum class TimeoutFallback {
  kActuatorsOff,  ///< "off": zero force; the P-16P lead screws hold the leg lengths
  kHoldLast,      ///< "hold_last": keep applying the last command
};

/// "off" | "hold_last"; throws std::invalid_argument.
TimeoutFallback ParseTimeoutFallback(const std::string& name);

/// Why a received force command cannot be applied; "" when it can.
/// Checks finiteness only: the magnitude is the actuator's to saturate.
std::string ForceCommandProblem(const Vector6d& force_n);

/// Real-time mode: holds the newest valid command; once none arrived for
/// longer than the timeout (or none ever arrived) applies the fallback.
class RealTimeCommandHold {
 public:
  RealTimeCommandHold(double command_timeout_s, TimeoutFallback fallback);

  void OnCommand(const Vector6d& force_n, double now_s);

  struct Decision {
    Vector6d force_cmd_n = Vector6d::Zero();
    bool actuators_off = false;
    bool timed_out = false;  ///< the fallback is in force
  };
  Decision Decide(double now_s) const;

 private:
  double timeout_s_;
  TimeoutFallback fallback_;
  bool have_command_ = false;
  double last_command_s_ = 0.0;
  Vector6d last_force_n_ = Vector6d::Zero();
};

/// Lockstep mode: a command answers tick k iff its sample_utime equals the
/// utime of the sensor sample of tick k.
enum class LockstepMatch { kAnswer, kStale, kFuture };
LockstepMatch MatchLockstepCommand(int64_t awaited_sample_utime, int64_t command_sample_utime);

}  // namespace stewart
