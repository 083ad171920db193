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

double DcMotorEffectiveDuty(const DcMotorParams& motor, double duty) {
  if (!std::isfinite(duty)) return 0.0;
  const double magnitude = std::min(std::abs(duty), 1.0);
  const double excess = magnitude - motor.dead_band_duty;
  if (excess <= 0.0) return 0.0;
  return std::copysign(excess / (1.0 - motor.dead_band_duty), duty);
}

double DcMotorDriveForce(const DcMotorParams& motor, double duty) {
  return DcMotorEffectiveDuty(motor, duty) * DcMotorForceAtFullDuty(motor);
}

double DcMotorDutyForDriveForce(const DcMotorParams& motor, double drive_force_n) {
  if (!std::isfinite(drive_force_n) || drive_force_n == 0.0) return 0.0;
  const double u = std::min(std::abs(drive_force_n) / DcMotorForceAtFullDuty(motor), 1.0);
  return std::copysign(motor.dead_band_duty + (1.0 - motor.dead_band_duty) * u, drive_force_n);
}

Vector6d DcMotorDutyForDriveForce(const DcMotorParams& motor, const Vector6d& drive_force_n) {
  Vector6d duty;
  for (int i = 0; i < kNumLegs; ++i) duty(i) = DcMotorDutyForDriveForce(motor, drive_force_n(i));
  return duty;
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

double ModelLegDampingNspm(const ActuatorConfig& actuators) {
  double b = actuators.viscous_friction_nspm;
  if (actuators.kind == ActuatorKind::kDcMotor) b += DcMotorBackEmfDampingNspm(actuators.motor);
  return b;
}

}  // namespace stewart
