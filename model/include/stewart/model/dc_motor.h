#pragma once
// The DC-motor leg's input map (docs/model.md, "The P-16P actuator"): PWM duty
// -> H-bridge output -> motor force on the leg,
//
//   u_eff(duty) = sign(duty) max(0, |duty| - d0) / (1 - d0)       (dead band d0)
//   V           = u_eff (V_s - V_drop)                            (bridge, V)
//   F_motor     = (F_stall / V_rated) V - b Ld,   b = F_stall / v_noload,
//
// Ld the leg speed (m/s). The stack's control input is the first term, the
// motor's drive force F_drive = (F_stall / V_rated) V (N): linear in u_eff,
// boxed by its value at full duty. Its back-EMF damping b and rotor inertia
// (DcMotorParams::reflected_mass_kg, in M through the dynamics) are part of
// the stack's model, so the paper's filter keeps its closed form on F_drive.
#include "stewart/model/actuator_params.h"
#include "stewart/model/types.h"

namespace stewart {

/// A force -> duty map of the H-bridge driver (hw_bridge's, and plant_sim's
/// when it stands in for hw_bridge): F is clamped to +-force_limit_n, then
///   duty = sign(F) (dead_band_duty + (1 - dead_band_duty) |F| / force_at_full_duty_n),
/// 0 for F = 0 or non-finite F, clamped to +-max_duty.
struct ForceToDutyMap {
  double force_limit_n = 0.0;
  double force_at_full_duty_n = 1.0;
  double dead_band_duty = 0.0;
  double max_duty = 1.0;
};
double DutyForForce(const ForceToDutyMap& map, double force_n);
Vector6d DutyForForce(const ForceToDutyMap& map, const Vector6d& force_n);

/// Its inverse, the bridge and motor as the map assumes them: u_eff(duty)
/// = sign(duty) max(0, min(|duty|, 1) - dead_band_duty) / (1 - dead_band_duty)
/// (0 for a non-finite duty) and the force u_eff force_at_full_duty_n (N).
double EffectiveDuty(const ForceToDutyMap& map, double duty);
double ForceForDuty(const ForceToDutyMap& map, double duty);

/// Back-EMF damping b = F_stall / v_noload (N s/m).
double DcMotorBackEmfDampingNspm(const DcMotorParams& motor);

/// Drive force at duty 1 (N): F_stall (V_s - V_drop) / V_rated.
double DcMotorForceAtFullDuty(const DcMotorParams& motor);

/// The motor's own map: force at full duty DcMotorForceAtFullDuty, its dead
/// band, forces clamped to the force at full duty, duty to [-1, 1].
ForceToDutyMap DcMotorDutyMap(const DcMotorParams& motor);

/// u_eff of a duty (clamped to [-1, 1]); 0 inside the dead band.
double DcMotorEffectiveDuty(const DcMotorParams& motor, double duty);

/// The drive force a duty gives, F_drive = u_eff F_full (N).
double DcMotorDriveForce(const DcMotorParams& motor, double duty);

/// The duty that gives drive force F (the inverse of DcMotorDriveForce):
/// sign(F) (d0 + (1 - d0) |F| / F_full), 0 for F = 0, clamped to [-1, 1].
/// Non-finite F gives 0.
double DcMotorDutyForDriveForce(const DcMotorParams& motor, double drive_force_n);
Vector6d DcMotorDutyForDriveForce(const DcMotorParams& motor, const Vector6d& drive_force_n);

/// The leg damping the stack models (N s/m): the screw's viscous friction
/// plus, for a DC motor, the back-EMF damping.
double ModelLegDampingNspm(const ActuatorConfig& actuators);

}  // namespace stewart
