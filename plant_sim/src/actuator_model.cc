#include "stewart/plant_sim/actuator_model.h"

#include <algorithm>
#include <cmath>

#include "stewart/model/dc_motor.h"
#include "stewart/model/dynamics.h"
#include "stewart/plant_sim/plant_dynamics.h"

namespace stewart {

Vector6d SaturateForce(const ActuatorConfig& actuators, const Vector6d& force_cmd_n) {
  const double f_max = actuators.force_limit_n;
  return force_cmd_n.cwiseMax(-f_max).cwiseMin(f_max);
}

Vector6d FrictionForce(const ActuatorConfig& actuators, const Vector6d& leg_speed_mps) {
  return LegViscousFriction(actuators.viscous_friction_nspm, leg_speed_mps);
}

Vector6d CoulombFrictionForce(const Vector6d& coulomb_friction_n, const Vector6d& leg_speed_mps) {
  return -coulomb_friction_n.cwiseProduct(
      (leg_speed_mps / kCoulombSpeedScaleMps).array().tanh().matrix());
}

Vector6d EndStopForce(const ActuatorConfig& actuators, const Vector6d& leg_length_m,
                      const Vector6d& leg_speed_mps) {
  const double l_min = actuators.min_length_m;
  const double l_max = actuators.min_length_m + actuators.stroke_m;
  const double k = actuators.endstop_stiffness_npm;
  const double c = actuators.endstop_damping_nspm;
  Vector6d force = Vector6d::Zero();
  for (int i = 0; i < kNumLegs; ++i) {
    const double below = l_min - leg_length_m(i);
    const double above = leg_length_m(i) - l_max;
    if (below > 0.0) {
      force(i) = std::max(0.0, k * below - c * leg_speed_mps(i));
    } else if (above > 0.0) {
      force(i) = std::min(0.0, -k * above - c * leg_speed_mps(i));
    }
  }
  return force;
}

double EndStopPotentialEnergy(const ActuatorConfig& actuators, const Vector6d& leg_length_m) {
  const double l_min = actuators.min_length_m;
  const double l_max = actuators.min_length_m + actuators.stroke_m;
  double energy_j = 0.0;
  for (int i = 0; i < kNumLegs; ++i) {
    const double d = std::max({0.0, l_min - leg_length_m(i), leg_length_m(i) - l_max});
    energy_j += 0.5 * actuators.endstop_stiffness_npm * d * d;
  }
  return energy_j;
}

Vector6d LegLockForce(const ActuatorConfig& actuators, const Vector6d& leg_length_m,
                      const Vector6d& leg_speed_mps, const Vector6d& lock_length_m) {
  return -actuators.endstop_stiffness_npm * (leg_length_m - lock_length_m) -
         actuators.endstop_damping_nspm * leg_speed_mps;
}

Vector6d DcMotorDriveForce(const DcMotorParams& motor, const Vector6d& duty, bool power_off) {
  Vector6d force = Vector6d::Zero();
  if (power_off) return force;
  for (int i = 0; i < kNumLegs; ++i) force(i) = DcMotorDriveForce(motor, duty(i));
  return force;
}

bool DcMotorEnergised(const DcMotorParams& motor, double duty, bool power_off) {
  return !power_off && DcMotorEffectiveDuty(motor, duty) != 0.0;
}

double DcMotorHoldDampingNspm(const DcMotorParams& motor) {
  return 2.0 * std::sqrt(motor.lock_stiffness_npm * std::max(motor.reflected_mass_kg, 0.1));
}

Vector6d DcMotorLegForce(const ActuatorConfig& actuators, const PlantInputs& inputs,
                         const Vector6d& leg_length_m, const Vector6d& leg_speed_mps) {
  const DcMotorParams& motor = actuators.motor;
  const double b_emf = inputs.legs_locked ? 0.0 : DcMotorBackEmfDampingNspm(motor);
  const double c_hold = DcMotorHoldDampingNspm(motor);
  Vector6d force;
  for (int i = 0; i < kNumLegs; ++i) {
    const double ld = leg_speed_mps(i);
    const double dry = DcMotorEnergised(motor, inputs.duty(i), inputs.legs_locked)
                           ? motor.coulomb_friction_n
                           : motor.back_drive_force_n;
    force(i) = -b_emf * ld - dry * std::tanh(ld / kCoulombSpeedScaleMps);
    if (inputs.leg_held[static_cast<std::size_t>(i)]) {
      force(i) +=
          -motor.lock_stiffness_npm * (leg_length_m(i) - inputs.hold_length_m(i)) - c_hold * ld;
    }
  }
  return force;
}

Vector6d DcMotorUndrivenResistanceN(const ActuatorConfig& actuators,
                                    const Vector6d& coulomb_error_n, bool power_off,
                                    const Vector6d& leg_length_m, const Vector6d& leg_speed_mps) {
  PlantInputs undriven;  // zero duty, no leg held
  undriven.legs_locked = power_off;
  const Vector6d force_n = DcMotorLegForce(actuators, undriven, leg_length_m, leg_speed_mps) +
                           FrictionForce(actuators, leg_speed_mps) +
                           CoulombFrictionForce(coulomb_error_n, leg_speed_mps);
  return -force_n.cwiseProduct(leg_speed_mps.cwiseSign());
}

Vector6d ForceLagRate(const ActuatorConfig& actuators, const Vector6d& force_sat_n,
                      const Vector6d& force_motor_n) {
  return (force_sat_n - force_motor_n) / actuators.force_lag_s;
}

}  // namespace stewart
