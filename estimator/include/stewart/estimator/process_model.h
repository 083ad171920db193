#pragma once
// Process model of the EKF: the platform's forward dynamics driven by the
// applied leg forces (paper eq. 2), with the lead-screw friction the
// actuators lose:
//
//   qdd = M(q)^-1 (H(q) (F - c_v ld) - C(q,qd) qd - G(q)),  ld = J_l qd = H^T qd,
//
// F in N (leg forces, clipped to the actuator limit by the caller), c_v in
// N/(m/s), qdd in m/s^2 and rad/s^2 (Euler accelerations).
#include "stewart/model/platform_params.h"
#include "stewart/model/rotation.h"
#include "stewart/model/shared_dynamics_terms.h"
#include "stewart/model/types.h"

namespace stewart {

Vector6d DynamicsAcceleration(const PlatformParams& params, double friction_nspm, const Vector6d& q,
                              const Vector6d& qd, const Vector6d& force_n);

/// qdd and its Jacobians, from one model evaluation and one factor of M:
/// dqdd/dq analytic from the force, gravity and friction terms (the inertial
/// part -M^-1 d(M qdd + C qd)/dq, O(|qdd| + |qd|^2), is left out),
/// dqdd/dqd from the friction term only (the Coriolis part is O(|qd|)); the
/// derivation and the measured size of what is left out: docs/estimator.md,
/// "The Jacobian dqdd/dq". Under force control the platform is a neutrally or
/// un-stably balanced body, so dqdd/dq must be in the covariance propagation.
void DynamicsAccelerationJacobians(const PlatformParams& params, double friction_nspm,
                                   const Vector6d& q, const Vector6d& qd, const Vector6d& force_n,
                                   Vector6d* qdd, Matrix6d* dqdd_dq, Matrix6d* dqdd_dqd);
/// The same, given the sines and cosines of q's angles.
void DynamicsAccelerationJacobians(const PlatformParams& params, double friction_nspm,
                                   const Vector6d& q, const EulerAngleTrig& trig,
                                   const Vector6d& qd, const Vector6d& force_n, Vector6d* qdd,
                                   Matrix6d* dqdd_dq, Matrix6d* dqdd_dqd);
/// The same with the model error d added to H F (model/disturbance.h):
/// qdd = M^-1 (H (F - c_v ld) + d - C qd - G), and dqdd/dd = M^-1 in
/// `m_inv`. d is constant in q, so the other Jacobians are those above (the
/// inertial part -M^-1 dM/dq qdd, which d enters, is left out as there).
/// `shared`: the model terms through it when not null (its parameters are
/// `params`: AttachSharedTerms). `dqdd_dforce`, when not null: M^-1 H.
/// `h`, when not null: H (leg forces to generalised forces, N -> N and
/// N m per rad).
void DynamicsAccelerationJacobians(const PlatformParams& params, double friction_nspm,
                                   const Vector6d& q, const EulerAngleTrig& trig,
                                   const Vector6d& qd, const Vector6d& force_n,
                                   const Vector6d& disturbance_n, Vector6d* qdd, Matrix6d* dqdd_dq,
                                   Matrix6d* dqdd_dqd, Matrix6d* m_inv,
                                   SharedDynamicsTerms* shared = nullptr,
                                   Matrix6d* dqdd_dforce = nullptr, Matrix6d* h = nullptr);

}  // namespace stewart
