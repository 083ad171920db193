#include "stewart/plant_sim/plant_dynamics.h"

#include "stewart/plant_sim/actuator_model.h"

namespace stewart {

void PlantDerivative(const PlantModel& model, const PlantInputs& inputs, const PlantStateVector& x,
                     PlantRates* rates) {
  EvaluateDynamics(model.platform, PoseOf(x), VelocityOf(x), &rates->terms);
  PlantDerivativeGivenTerms(model, inputs, x, rates);
}

void PlantDerivativeGivenTerms(const PlantModel& model, const PlantInputs& inputs,
                               const PlantStateVector& x, PlantRates* rates) {
  const Vector6d qd = VelocityOf(x);
  const DynamicsTerms& terms = rates->terms;
  const Vector6d& leg_length_m = terms.leg_length_m;
  const Vector6d leg_speed_mps = terms.H.transpose() * qd;  // Ld = J_l qd, H = J_l^T

  const ActuatorConfig& act = model.actuators;
  const bool dc_motor = act.kind == ActuatorKind::kDcMotor;
  const Vector6d force_sat_n = model.actuator_errors.force_gain.cwiseProduct(
      dc_motor ? DcMotorDriveForce(act.motor, inputs.duty, inputs.legs_locked)
               : SaturateForce(act, inputs.force_cmd_n));
  Vector6d force_motor_n;
  Vector6d force_motor_rate = Vector6d::Zero();
  if (act.force_lag_s > 0.0) {
    force_motor_n = MotorForceOf(x);
    force_motor_rate = ForceLagRate(act, force_sat_n, force_motor_n);
  } else {
    force_motor_n = force_sat_n;
  }

  Vector6d leg_force_n = force_motor_n + FrictionForce(act, leg_speed_mps) +
                         EndStopForce(act, leg_length_m, leg_speed_mps);
  if (!model.actuator_errors.coulomb_friction_n.isZero()) {
    leg_force_n += CoulombFrictionForce(model.actuator_errors.coulomb_friction_n, leg_speed_mps);
  }
  if (dc_motor) {
    leg_force_n += DcMotorLegForce(act, inputs, leg_length_m, leg_speed_mps);
  } else if (inputs.legs_locked) {
    leg_force_n += LegLockForce(act, leg_length_m, leg_speed_mps, inputs.lock_length_m);
  }
  rates->leg_force_n = leg_force_n;
  rates->x_dot.segment<6>(0) = qd;
  if (inputs.external_wrench.isZero()) {
    rates->x_dot.segment<6>(6) = ForwardDynamics(terms, leg_force_n);
  } else {
    rates->x_dot.segment<6>(6) = ForwardDynamics(
        terms, leg_force_n, GeneralisedForceOfWrench(PoseOf(x), inputs.external_wrench));
  }
  rates->x_dot.segment<6>(12) = force_motor_rate;
}

ForceToDutyMap PlantModel::DriverOf(const ActuatorConfig& actuators) {
  ForceToDutyMap map;
  if (actuators.kind == ActuatorKind::kDcMotor) map = DcMotorDutyMap(actuators.motor);
  map.force_limit_n = actuators.force_limit_n;
  return map;
}

double PlantMechanicalEnergy(const PlantModel& model, const Vector6d& q, const Vector6d& qd) {
  DynamicsTerms terms;
  EvaluateDynamics(model.platform, q, qd, &terms);
  return KineticEnergy(terms, qd) + PotentialEnergy(model.platform, q) +
         EndStopPotentialEnergy(model.actuators, terms.leg_length_m);
}

}  // namespace stewart
