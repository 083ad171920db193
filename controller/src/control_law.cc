#include "stewart/controller/control_law.h"

namespace stewart {

Vector6d PdAcceleration(const ControllerConfig& gains, const Vector6d& q, const Vector6d& qd,
                        const Setpoint& setpoint) {
  return setpoint.qdd_des - gains.kp.cwiseProduct(q - setpoint.q_des) -
         gains.kd.cwiseProduct(qd - setpoint.qd_des);
}

Vector6d NominalForce(const PlatformParams& platform, const ControllerConfig& gains,
                      const Vector6d& q, const Vector6d& qd, const Setpoint& setpoint,
                      DynamicsTerms* terms) {
  return NominalForce(platform, gains, q, qd, Vector6d::Zero(), setpoint, terms);
}

Vector6d NominalForce(const PlatformParams& platform, const ControllerConfig& gains,
                      const Vector6d& q, const Vector6d& qd, const Vector6d& disturbance_n,
                      const Setpoint& setpoint, DynamicsTerms* terms, SharedDynamicsTerms* shared) {
  EvaluateDynamics(platform, shared, q, qd, terms);
  // The legs lose LegViscousFriction on the way: command it on top.
  return InverseDynamics(*terms, PdAcceleration(gains, q, qd, setpoint), disturbance_n) -
         LegViscousFriction(gains.leg_friction_nspm, terms->H.transpose() * qd);
}

}  // namespace stewart
