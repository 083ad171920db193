#pragma once
// The guard classes' limits from the config's `guard:` section and the
// actuator's own keys (its stroke, its command_timeout_s).
#include <cmath>
#include <cstdint>

#include "stewart/guard/actuator_guard.h"
#include "stewart/guard/guard_config.h"
#include "stewart/guard/safe_command_acceptor.h"

namespace stewart {

inline int64_t SecondsToMicros(double s) { return std::llround(s * 1e6); }

/// `command_timeout_s`: plant_sim's or hw_bridge's own: the age beyond which
/// a command is never applied.
inline SafeCommandAcceptorLimits AcceptorLimitsOf(const GuardConfig& g, double command_timeout_s) {
  SafeCommandAcceptorLimits l;
  l.command_max_age_us = SecondsToMicros(command_timeout_s);
  l.session_max_age_us = SecondsToMicros(g.session_max_age_s);
  l.session_silence_us = SecondsToMicros(g.session_silence_s);
  l.session_silence_wall_us = SecondsToMicros(g.session_silence_wall_s);
  return l;
}

/// The stroke ends (joint to joint, m) the actuator's readings are judged by.
inline ActuatorGuardLimits ActuatorGuardLimitsOf(const GuardConfig& g, double min_length_m,
                                                 double max_length_m) {
  ActuatorGuardLimits l;
  l.min_length_m = min_length_m;
  l.max_length_m = max_length_m;
  l.stroke_margin_m = g.leg_stroke_margin_m;
  l.speed_cap_mps = g.leg_speed_cap_mps;
  l.force_limit_n = g.leg_force_limit_n;
  return l;
}

}  // namespace stewart
