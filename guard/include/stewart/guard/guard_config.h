#pragma once
// The `guard:` section of the config: what the actuators (plant_sim,
// hw_bridge) accept and where they stop on their own (docs/operations.md,
// "Trust model"). The stroke ends come from `actuators`, the age beyond which
// a command is never applied from each process's command_timeout_s.
namespace stewart {

struct GuardConfig {
  // The last-line guard, on the actuators' own readings.
  /// A leg reading closer than this to a stroke end trips the guard (m).
  double leg_stroke_margin_m = 0.005;
  /// A leg speed (from the pots) above this trips it (m/s).
  double leg_speed_cap_mps = 0.3;
  /// A commanded leg force above this, in magnitude, trips it (N).
  double leg_force_limit_n = 20.0;

  // Which safety session the actuators follow.
  /// A session announcement whose utime is older than this against the
  /// receiver's newest sample adopts or renews nothing (s of stack time).
  double session_max_age_s = 0.25;
  /// Another session may be adopted only after the current one has gone
  /// this long without a fresh announcement, in stack time ...
  double session_silence_s = 0.3;
  /// ... or in wall time (s): in lockstep, stack time stops with the loop.
  double session_silence_wall_s = 1.5;
};

}  // namespace stewart
