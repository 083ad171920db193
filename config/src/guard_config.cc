#include "stewart/config/sections.h"

namespace stewart {

GuardConfig ParseGuardConfig(const ConfigNode& guard) {
  GuardConfig g;
  g.leg_stroke_margin_m = guard.NonNegativeDouble("leg_stroke_margin_m");
  g.leg_speed_cap_mps = guard.PositiveDouble("leg_speed_cap_mps");
  g.leg_force_limit_n = guard.PositiveDouble("leg_force_limit_n");
  g.session_max_age_s = guard.PositiveDouble("session_max_age_s");
  g.session_silence_s = guard.PositiveDouble("session_silence_s");
  g.session_silence_wall_s = guard.PositiveDouble("session_silence_wall_s");
  // Microsecond fields downstream: a limit below 1 us would round to 0.
  for (const char* key : {"session_max_age_s", "session_silence_s", "session_silence_wall_s"}) {
    if (guard.PositiveDouble(key) < 1e-3) guard.Fail(key, "must be at least 0.001 s");
  }
  // A session is renewed at least every 100 ms of stack time (the safety
  // process's announcement period): a silence shorter than the freshness
  // window would drop a live session between two of its announcements.
  if (g.session_silence_s < g.session_max_age_s) {
    guard.Fail("session_silence_s", "must not be below guard.session_max_age_s");
  }
  return g;
}

}  // namespace stewart
