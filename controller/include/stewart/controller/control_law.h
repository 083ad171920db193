#pragma once
// The nominal controller: feedback linearisation with a PD outer loop.
//
// Paper eq. 3 (commanded task-space acceleration, 1/s^2 and 1/s gains):
//   u = qdd_des - Kp (q - q_des) - Kd (qd - qd_des)
// and the leg forces that realise it through the model of paper eq. 2:
//   H(q) (F_des + F_friction) = M(q) u + C(q, qd) qd + G(q)
// solved by the model's InverseDynamics (no second copy of the dynamics);
// F_friction = LegViscousFriction(gains.leg_friction_nspm, H^T qd) is the
// legs' own viscous friction, cancelled when the config says so.
#include "stewart/controller/controller_config.h"
#include "stewart/controller/setpoint.h"
#include "stewart/model/dynamics.h"
#include "stewart/model/platform_params.h"
#include "stewart/model/shared_dynamics_terms.h"

namespace stewart {

/// u of paper eq. 3 (m/s^2, rad/s^2 Euler accelerations).
Vector6d PdAcceleration(const ControllerConfig& gains, const Vector6d& q, const Vector6d& qd,
                        const Setpoint& setpoint);

/// F_des (N, positive extends the leg) at (q, qd). `terms` receives the model
/// evaluated at (q, qd), so callers can reuse it. No heap allocation.
Vector6d NominalForce(const PlatformParams& platform, const ControllerConfig& gains,
                      const Vector6d& q, const Vector6d& qd, const Setpoint& setpoint,
                      DynamicsTerms* terms);
/// The same, cancelling the estimated model error d (model/disturbance.h):
///   H (F_des + F_friction) + d = M u + C qd + G.
/// `shared`: the model terms through it when not null (its parameters are
/// `platform`: AttachSharedTerms).
Vector6d NominalForce(const PlatformParams& platform, const ControllerConfig& gains,
                      const Vector6d& q, const Vector6d& qd, const Vector6d& disturbance_n,
                      const Setpoint& setpoint, DynamicsTerms* terms,
                      SharedDynamicsTerms* shared = nullptr);

}  // namespace stewart
