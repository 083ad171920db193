#include "stewart/hw_bridge/bringup.h"

#include <cmath>

#include "stewart/model/dc_motor.h"

namespace stewart::hw {

LegGuardLimits DefaultBringupGuard(double min_length_m, double max_length_m, double margin_m,
                                   const DcMotorParams& motor) {
  LegGuardLimits g;
  g.min_length_m = min_length_m;
  g.max_length_m = max_length_m;
  g.margin_m = margin_m;
  g.speed_cap_mps = 0.05;
  if (motor.stall_force_n > 0.0 && motor.no_load_speed_mps > 0.0) {
    const double full_speed_mps = DcMotorForceAtFullDuty(motor) / DcMotorBackEmfDampingNspm(motor);
    if (std::isfinite(full_speed_mps) && full_speed_mps > 0.0)
      g.speed_cap_mps = 2.0 * full_speed_mps;
  }
  return g;
}

}  // namespace stewart::hw
