#pragma once
// The P-16P linear actuator as the simulator sees it (docs/simulation.md,
// "Actuators"). Every quantity is per leg, along the leg axis, positive
// extending; lengths joint to joint (m), speeds dL/dt (m/s), forces (N).
#include "stewart/model/actuator_params.h"
#include "stewart/model/types.h"
#include "stewart/plant_sim/truth.h"

namespace stewart {

/// The motor force a command can produce: clamp(F_cmd, -F_max, F_max).
Vector6d SaturateForce(const ActuatorConfig& actuators, const Vector6d& force_cmd_n);

/// Lead-screw viscous friction: F_f = -b Ld.
Vector6d FrictionForce(const ActuatorConfig& actuators, const Vector6d& leg_speed_mps);

/// Dry friction of the lead screw and gearbox, smoothed so the right-hand
/// side stays Lipschitz: F = -F_c tanh(Ld / kCoulombSpeedScaleMps) (truth.h).
Vector6d CoulombFrictionForce(const Vector6d& coulomb_friction_n, const Vector6d& leg_speed_mps);

/// Stiff, damped end-stop at each stroke end. With penetration d > 0 beyond
/// l_min (or l_max): F = k d - c Ld pushing back into the stroke, clamped so
/// the stop can push but never pull (no sticking on the way out).
/// Zero inside [l_min, l_min + stroke].
Vector6d EndStopForce(const ActuatorConfig& actuators, const Vector6d& leg_length_m,
                      const Vector6d& leg_speed_mps);

/// Potential energy of the end-stop springs, sum 1/2 k d^2 (J); with zero
/// damping the stops are conservative and this closes the energy balance.
double EndStopPotentialEnergy(const ActuatorConfig& actuators, const Vector6d& leg_length_m);

/// The lead screw of an unpowered P-16P is not back-drivable: modelled as a
/// stiff, damped spring that holds each leg at `lock_length_m`, with the
/// end-stop stiffness and damping: F = -k (L - L_lock) - c Ld.
Vector6d LegLockForce(const ActuatorConfig& actuators, const Vector6d& leg_length_m,
                      const Vector6d& leg_speed_mps, const Vector6d& lock_length_m);

/// DC motor: the drive force of each leg's duty, u_eff(duty) F_full (N);
/// zero when the power is off.
Vector6d DcMotorDriveForce(const DcMotorParams& motor, const Vector6d& duty, bool power_off);

/// True iff the duty energises the motor (outside the dead band, power on).
bool DcMotorEnergised(const DcMotorParams& motor, double duty, bool power_off);

/// DC motor: the leg forces besides the drive force and the screw's viscous
/// friction (N): back-EMF damping -b_emf Ld (power on), the screw's dry
/// friction -F tanh(Ld / kCoulombSpeedScaleMps) with F = coulomb_friction_n
/// while energised and back_drive_force_n while not, and for held legs the
/// screw's spring -k (L - L_held) - c Ld, c critical with the reflected mass.
struct PlantInputs;
Vector6d DcMotorLegForce(const ActuatorConfig& actuators, const PlantInputs& inputs,
                         const Vector6d& leg_length_m, const Vector6d& leg_speed_mps);

/// Damping of a held leg's spring (N s/m): critical for the reflected mass
/// (at least 0.1 kg, so a massless rotor still damps).
double DcMotorHoldDampingNspm(const DcMotorParams& motor);

/// DC motor: the force opposing each leg's motion were its motor not
/// energised and no screw holding it (N, >= 0): -sign(Ld) times the sum of
/// DcMotorLegForce at zero duty (back-EMF while powered, dry friction at the
/// back-drive force), the screw's viscous friction and the truth's extra dry
/// friction `coulomb_error_n`. Below the back-drive force it is the speed
/// range in which the smoothed friction, not the screw, decides how fast a
/// leg creeps.
Vector6d DcMotorUndrivenResistanceN(const ActuatorConfig& actuators,
                                    const Vector6d& coulomb_error_n, bool power_off,
                                    const Vector6d& leg_length_m, const Vector6d& leg_speed_mps);

/// First-order force lag tau dF/dt = F_sat - F (tau = force_lag_s > 0).
Vector6d ForceLagRate(const ActuatorConfig& actuators, const Vector6d& force_sat_n,
                      const Vector6d& force_motor_n);

}  // namespace stewart
