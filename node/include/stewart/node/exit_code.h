#pragma once
// The exit statuses of every process of the stack (documented once, in
// docs/operations.md, "Processes"). tools/launch.sh and the tests read them.

namespace stewart {

enum class ExitCode : int {
  kOk = 0,                  ///< stopped by a signal, or reached its end
  kFault = 1,               ///< a runtime failure (LCM, device link, exception)
  kBadInput = 2,            ///< bad config, truth or command-line argument
  kLockstepTimeout = 3,     ///< plant_sim lockstep: no command within the timeout
  kIntegrationFailure = 4,  ///< plant_sim: the integrator failed
  kRefused = 5,             ///< stewart_ctl: the supervisor refused the command
};

constexpr int ToInt(ExitCode code) { return static_cast<int>(code); }

}  // namespace stewart
