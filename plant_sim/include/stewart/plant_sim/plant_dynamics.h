#pragma once
// The simulator's ODE right-hand side: the model's task-space dynamics
// (model/dynamics.h, paper eq. 2) driven by the actuator model.
//
//   x = [q (m, rad), qd (m/s, rad/s), F_motor (N)]            (18 states)
//   qd'      = M^-1 (H F_leg - C qd - G),
//   qd'      = M^-1 (H F_leg + Q_ext - C qd - G)   with an external wrench,
//   F_leg    = F_motor - b Ld - F_c tanh(Ld / v_c) + F_endstop(L, Ld) [+ F_lock(L, Ld)],
//              Ld = H^T qd,
//   F_motor' = (k sat(F_cmd) - F_motor) / tau   if force_lag_s = tau > 0,
//   F_motor  = k sat(F_cmd) (held in the state, rate 0) otherwise; Plant then
//              integrates only q and qd (docs/simulation.md, "Integrator").
// k (force gain) and F_c (Coulomb friction) come from the truth
// (truth.h); the model's defaults are k = 1, F_c = 0.
//
// With a DC-motor actuator (ActuatorKind::kDcMotor, model/dc_motor.h) the
// input is the PWM duty and sat(F_cmd) becomes the drive force of the duty,
// F_drive = u_eff(duty) F_full; the leg force adds the back-EMF damping
// -b_emf Ld (not when the power is off: open terminals), the screw's dry
// friction (coulomb_friction_n while the motor is energised,
// back_drive_force_n while it is not: the screw self-locks) and, for a leg
// the screw holds (PlantInputs::leg_held), a stiff spring to its held
// length; the rotor's reflected mass is in M (PlatformParams::leg).
#include <Eigen/Core>
#include <array>

#include "stewart/model/actuator_params.h"
#include "stewart/model/dc_motor.h"
#include "stewart/model/dynamics.h"
#include "stewart/model/platform_params.h"
#include "stewart/plant_sim/truth.h"

namespace stewart {

constexpr int kPlantStateSize = 18;
using PlantStateVector = Eigen::Matrix<double, kPlantStateSize, 1>;

/// The physical plant: rigid-body model plus actuators.
struct PlantModel {
  PlantModel() = default;
  PlantModel(const PlatformParams& platform_params, const ActuatorConfig& actuator_config,
             const ActuatorTruth& errors = ActuatorTruth{}, double delay_s = 0.0)
      : platform(platform_params),
        actuators(actuator_config),
        actuator_errors(errors),
        command_delay_s(delay_s),
        duty_map(DriverOf(actuator_config)) {}

  /// The driver that matches these actuators exactly (its own motor map).
  static ForceToDutyMap DriverOf(const ActuatorConfig& actuators);

  PlatformParams platform;
  ActuatorConfig actuators;
  ActuatorTruth actuator_errors;
  double command_delay_s = 0.0;  ///< a command acts this long after it is set
  /// DC motor only: how Plant::SetForceCommand turns a force into a duty
  /// (the H-bridge driver plant_sim stands in for; the stack's own map, from
  /// its config, not the truth's).
  ForceToDutyMap duty_map;
};

/// The plant of a truth.
inline PlantModel PlantModelOf(const PlantTruth& truth) {
  return PlantModel{truth.platform, truth.actuators, truth.actuator_errors,
                    truth.latency.total_s()};
}

/// Inputs held constant over one integration interval (zero-order hold).
struct PlantInputs {
  Vector6d force_cmd_n = Vector6d::Zero();  ///< ideal force source: commanded forces (N)
  Vector6d duty = Vector6d::Zero();         ///< DC motor: PWM duty in [-1, 1]
  /// Unpowered. Ideal force source: the lead screws hold every leg at
  /// lock_length_m. DC motor: no drive and no back-EMF; each leg self-locks
  /// as leg_held says.
  bool legs_locked = false;
  Vector6d lock_length_m = Vector6d::Zero();
  /// DC motor: legs the self-locking screw holds, at hold_length_m (Plant
  /// decides at each step: UpdateSelfLocking).
  std::array<bool, kNumLegs> leg_held{};
  Vector6d hold_length_m = Vector6d::Zero();
  /// External wrench on the platform, [force (N); torque (N m)] in {B},
  /// force through the origin of {P} (GeneralisedForceOfWrench).
  Vector6d external_wrench = Vector6d::Zero();
};

inline Eigen::Ref<const Vector6d> PoseOf(const PlantStateVector& x) { return x.segment<6>(0); }
inline Eigen::Ref<const Vector6d> VelocityOf(const PlantStateVector& x) { return x.segment<6>(6); }
inline Eigen::Ref<const Vector6d> MotorForceOf(const PlantStateVector& x) {
  return x.segment<6>(12);
}

/// Everything the right-hand side computed at one state.
struct PlantRates {
  PlantStateVector x_dot;
  Vector6d leg_force_n;  ///< total force along each leg, F_leg
  DynamicsTerms terms;
};

/// x_dot = f(x, inputs). No heap allocation.
void PlantDerivative(const PlantModel& model, const PlantInputs& inputs, const PlantStateVector& x,
                     PlantRates* rates);

/// The same, with rates->terms already evaluated at x's pose and velocity
/// (EvaluateDynamics is most of the cost and depends on nothing else):
/// actuator forces and qdd only.
void PlantDerivativeGivenTerms(const PlantModel& model, const PlantInputs& inputs,
                               const PlantStateVector& x, PlantRates* rates);

/// T + V + end-stop spring energy (J): constant when F_leg is conservative
/// (F = 0, no friction, no end-stop damping).
double PlantMechanicalEnergy(const PlantModel& model, const Vector6d& q, const Vector6d& qd);

}  // namespace stewart
