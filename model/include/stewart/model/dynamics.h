#pragma once
// Task-space rigid-body dynamics of the Stewart platform (paper eq. 2):
//
//   M(q) qdd + C(q, qd) qd + G(q) = H(q) F,   H = J_l^T,
//
// q = [x y z phi theta psi] (m, rad; Euler rates, see rotation.h),
// F = leg forces (N, positive extends the leg), M in kg / kg m / kg m^2,
// C qd and G in N / N m (generalised forces conjugate to q).
//
// Derived from one Lagrangian (platform rigid body + two bodies per leg,
// docs/model.md), so qd^T (Mdot - 2C) qd = 0 holds exactly (power balance),
// which the energy-based CBF relies on.
#include "stewart/model/kinematics.h"
#include "stewart/model/platform_params.h"
#include "stewart/model/types.h"

namespace stewart {

/// Everything a process needs from the model at one state.
struct DynamicsTerms {
  Matrix6d M;     ///< inertia matrix, symmetric positive definite
  Vector6d C_qd;  ///< Coriolis and centrifugal generalised force C(q,qd) qd
  Vector6d G;     ///< gravity generalised force dV/dq
  Matrix6d H;     ///< J_l^T: maps leg forces to generalised forces
  Vector6d leg_length_m;
  /// J_l-dot qd (m/s^2): the leg accelerations at qdd = 0, so that
  /// Ldd = H^T qdd + leg_bias_accel_mps2 (per leg, n . a_bias + L |nd|^2).
  Vector6d leg_bias_accel_mps2;
};

/// Evaluates M, C qd, G and H at (q, qd). No heap allocation.
void EvaluateDynamics(const PlatformParams& params, const Vector6d& q, const Vector6d& qd,
                      DynamicsTerms* terms);
DynamicsTerms EvaluateDynamics(const PlatformParams& params, const Vector6d& q, const Vector6d& qd);

/// qdd = M^-1 (H F - C qd - G), by the square-root-free Cholesky
/// factorisation M = L D L^T (linear_algebra6.h). NaN when M is not
/// positive definite (non-finite terms).
Vector6d ForwardDynamics(const DynamicsTerms& terms, const Vector6d& force_n);
/// The same with an external generalised force Q added to H F (N, N m):
/// qdd = M^-1 (H F + Q - C qd - G).
Vector6d ForwardDynamics(const DynamicsTerms& terms, const Vector6d& force_n,
                         const Vector6d& external_generalised_force);

/// The generalised force (conjugate to q, N and N m) of a wrench on the
/// platform: wrench_in_B = [force (N); torque (N m)], both in {B} axes, the
/// force acting through the origin of {P}. Q = [f; E(rpy)^T tau], E the Euler
/// rate matrix (omega_B = E rpy_dot, rotation.h), by virtual power.
Vector6d GeneralisedForceOfWrench(const Vector6d& q, const Vector6d& wrench_in_B);

/// The F that solves H F = M qdd + C qd + G, by Gaussian elimination with
/// partial pivoting (linear_algebra6.h). H is invertible away from singular
/// poses; NaN where it is not (callers check: the controller rejects a
/// non-finite force, the filter falls back).
Vector6d InverseDynamics(const DynamicsTerms& terms, const Vector6d& qdd);
/// The same with an external generalised force Q acting besides H F (the
/// model error d, model/disturbance.h): H F = M qdd + C qd + G - Q.
Vector6d InverseDynamics(const DynamicsTerms& terms, const Vector6d& qdd,
                         const Vector6d& external_generalised_force);

/// Viscous friction of the legs' lead screws, as leg forces (N):
///   F_friction = -b ld,   ld = J_l qd = H^T qd  (leg speed, m/s; b in N s/m).
/// The legs push with F + F_friction, so the plant obeys
///   M qdd + C qd + G = H (F - b H^T qd).
/// plant_sim integrates it; the controller and the filter include it in
/// their model of the plant (docs/model.md, "Leg friction").
inline Vector6d LegViscousFriction(double b_nspm, const Vector6d& leg_speed_mps) {
  return -b_nspm * leg_speed_mps;
}

/// Kinetic energy 1/2 qd^T M qd (J).
double KineticEnergy(const DynamicsTerms& terms, const Vector6d& qd);

/// Gravitational potential energy V(q) with dV/dq = G(q) (J, zero at z = 0
/// for every body).
double PotentialEnergy(const PlatformParams& params, const Vector6d& q);

}  // namespace stewart
