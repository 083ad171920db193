#include "stewart/model/dc_motor.h"

#include <algorithm>
#include <cmath>

namespace stewart {

double DcMotorBackEmfDampingNspm(const DcMotorParams& motor) {
  return motor.stall_force_n / motor.no_load_speed_mps;
}

double DcMotorForceAtFullDuty(const DcMotorParams& motor) {
  return motor.stall_force_n * (motor.supply_voltage_v - motor.bridge_drop_v) /
         motor.rated_voltage_v;
}

ForceToDutyMap DcMotorDutyMap(const DcMotorParams& motor) {
  ForceToDutyMap map;
  map.force_at_full_duty_n = DcMotorForceAtFullDuty(motor);
  map.force_limit_n = map.force_at_full_duty_n;
  map.dead_band_duty = motor.dead_band_duty;
  map.max_duty = 1.0;
  return map;
}

double EffectiveDuty(const ForceToDutyMap& map, double duty) {
  if (!std::isfinite(duty)) return 0.0;
  const double excess = std::min(std::abs(duty), 1.0) - map.dead_band_duty;
  if (excess <= 0.0) return 0.0;
  return std::copysign(excess / (1.0 - map.dead_band_duty), duty);
}

double ForceForDuty(const ForceToDutyMap& map, double duty) {
  return EffectiveDuty(map, duty) * map.force_at_full_duty_n;
}

double DutyForForce(const ForceToDutyMap& map, double force_n) {
  if (!std::isfinite(force_n) || force_n == 0.0) return 0.0;
  const double f = std::min(std::abs(force_n), map.force_limit_n);
  const double duty =
      map.dead_band_duty + (1.0 - map.dead_band_duty) * f / map.force_at_full_duty_n;
  return std::copysign(std::min(duty, map.max_duty), force_n);
}

Vector6d DutyForForce(const ForceToDutyMap& map, const Vector6d& force_n) {
  Vector6d duty;
  for (int i = 0; i < kNumLegs; ++i) duty(i) = DutyForForce(map, force_n(i));
  return duty;
}

double DcMotorEffectiveDuty(const DcMotorParams& motor, double duty) {
  return EffectiveDuty(DcMotorDutyMap(motor), duty);
}

double DcMotorDriveForce(const DcMotorParams& motor, double duty) {
  return ForceForDuty(DcMotorDutyMap(motor), duty);
}

double DcMotorDutyForDriveForce(const DcMotorParams& motor, double drive_force_n) {
  return DutyForForce(DcMotorDutyMap(motor), drive_force_n);
}

Vector6d DcMotorDutyForDriveForce(const DcMotorParams& motor, const Vector6d& drive_force_n) {
  return DutyForForce(DcMotorDutyMap(motor), drive_force_n);
}

double ModelLegDampingNspm(const ActuatorConfig& actuators) {
  double b = actuators.viscous_friction_nspm;
  if (actuators.kind == ActuatorKind::kDcMotor) b += DcMotorBackEmfDampingNspm(actuators.motor);
  return b;
}

}  // namespace stewart
