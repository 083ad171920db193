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

/// First-order force lag tau dF/dt = F_sat - F (tau = force_lag_s > 0).
Vector6d ForceLagRate(const ActuatorConfig& actuators, const Vector6d& force_sat_n,
                      const Vector6d& force_motor_n);

}  // namespace stewart
