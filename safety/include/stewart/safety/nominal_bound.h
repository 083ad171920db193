#pragma once
// The per-period bound on the nominal command (docs/safety.md, "One sample
// period"). The composed conditions hold in continuous time and, per step,
// restrict the acceleration along two directions (g_p, g_v) only: a nominal
// of 1e6 N passes them with an enormous acceleration along the other four,
// and within one zero-order-hold period of the plant that acceleration moves
// the state (and with it H, M and the barriers' weights) further than any
// limit allows. So before the conditions are solved, the nominal's model
// acceleration is bounded per axis:
//
//   qdd_des = M^-1 (H (F_des + F_friction) + d - C qd - G)      (m/s^2, rad/s^2)
//   |qdd_j| <= a_max_j = step_j / T                              (T: sample period)
//
// by scaling F_des towards F_0, the force of zero model acceleration:
//   F_bounded = F_0 + s (F_des - F_0),  s = min(1, min_j a_max_j / |qdd_des_j|),
// which scales qdd_des by s (qdd is affine in F and zero at F_0), keeps its
// direction, and leaves a nominal within the bound bit for bit unchanged.
// step_j is the largest velocity change per period the nominal may ask for:
// safety.per_period_velocity_step_mps (x, y, z; m/s) and
// safety.per_period_angular_step_radps (Euler angles; rad/s).
#include "stewart/model/dynamics.h"
#include "stewart/model/linear_algebra6.h"
#include "stewart/safety/leg_jacobian_factor.h"

namespace stewart::safety {

/// Largest nominal acceleration per axis (m/s^2, rad/s^2): step / period, or
/// +Inf on every axis when the bound is off (period or step <= 0).
Vector6d NominalAccelerationBound(double sample_period_s, double velocity_step_mps,
                                  double angular_step_radps);

/// Scales f_des (N, per leg) towards the zero-acceleration force at the
/// model terms `terms` (at q, qd) so that the model acceleration obeys
/// |qdd_j| <= max_accel_j; `inertia` the factor of terms.M (computed by the
/// caller, who needs it anyway), `h_factor` the step's factor of terms.H
/// (factored here if no solve of the step has yet), leg_speed_mps = H^T qd and
/// leg_friction_nspm the filter's leg friction; disturbance_n the estimated
/// model error d (N, N m). Returns the scale s in (0, 1] (1: f_bounded ==
/// f_des exactly). On a non-finite model acceleration or zero-acceleration
/// force, returns 0 and leaves *f_bounded = f_des: the caller treats the step
/// as invalid.
double BoundNominal(const DynamicsTerms& terms, const Cholesky6& inertia,
                    LegJacobianFactor* h_factor, const Vector6d& leg_speed_mps,
                    double leg_friction_nspm, const Vector6d& disturbance_n,
                    const Vector6d& max_accel, const Vector6d& f_des, Vector6d* f_bounded);

}  // namespace stewart::safety
