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

LegGuardLimits StrokeEndSearchGuard(double min_length_m, double max_length_m, double search_m,
                                    double speed_cap_mps) {
  constexpr double kEndZoneM = 5e-4;
  LegGuardLimits g;
  g.min_length_m = min_length_m - search_m;
  g.max_length_m = max_length_m + search_m;
  g.margin_m = kEndZoneM;
  g.speed_cap_mps = speed_cap_mps;
  return g;
}

int FaultMarginForSearch(const HwBridgeConfig& hw, double stroke_m, double search_m) {
  const double counts_per_m = (hw.adc_extended - hw.adc_retracted).cwiseAbs().maxCoeff() / stroke_m;
  return hw.adc_fault_margin_counts + static_cast<int>(std::ceil(search_m * counts_per_m));
}

}  // namespace stewart::hw
