// Paper eq. 3 and H F_des = M u + C qd + G on known values, and the closed
// loop with the model: the platform converges to a reachable setpoint.
#include "stewart/controller/control_law.h"

#include <gtest/gtest.h>

#include "stewart/config/default_config.h"

namespace stewart {
namespace {

TEST(ControlLaw, PdAccelerationOnKnownValues) {
  ControllerConfig gains;
  gains.kp << 1, 2, 3, 4, 5, 6;
  gains.kd << 10, 20, 30, 40, 50, 60;
  Setpoint sp;
  sp.q_des << 0.1, 0, 0.4, 0, 0, 0;
  sp.qd_des << 0, 0, 0, 0, 0, 0.5;
  sp.qdd_des << 0, 0, 0, 0, 0, 1.0;
  Vector6d q;
  q << 0.0, 0.2, 0.4, 0.0, 0.0, 0.0;
  Vector6d qd;
  qd << 0.0, 0.0, 0.1, 0.0, 0.0, 0.0;
  const Vector6d u = PdAcceleration(gains, q, qd, sp);
  // u_x = -1 (0 - 0.1); u_y = -2 (0.2); u_z = -30 (0.1); u_psi = 1 - 60 (0 - 0.5).
  EXPECT_DOUBLE_EQ(u(0), 0.1);
  EXPECT_DOUBLE_EQ(u(1), -0.4);
  EXPECT_DOUBLE_EQ(u(2), -3.0);
  EXPECT_DOUBLE_EQ(u(3), 0.0);
  EXPECT_DOUBLE_EQ(u(4), 0.0);
  EXPECT_DOUBLE_EQ(u(5), 31.0);
}

TEST(ControlLaw, AtTheSetpointAtRestHoldsAgainstGravity) {
  const StackConfig& c = DefaultStackConfig();
  Vector6d pose;
  pose << 0.03, -0.02, 0.45, 0.05, -0.04, 0.1;
  DynamicsTerms terms;
  const Vector6d f = NominalForce(c.platform, c.controller, pose, Vector6d::Zero(),
                                  Setpoint::HoldAt(pose), &terms);
  // Zero velocity and u = 0: H F = G, i.e. the legs carry the weight only.
  EXPECT_LT((terms.H * f - terms.G).norm(), 1e-9 * terms.G.norm());
  // The platform and legs weigh a few N: every leg pushes up (extends).
  EXPECT_GT(terms.G(2), 0.0);
  EXPECT_GT(f.minCoeff(), 0.0);
}

TEST(ControlLaw, SolvesTheDynamicsEquation) {
  const StackConfig& c = DefaultStackConfig();
  Vector6d q, qd;
  q << 0.02, 0.01, 0.42, 0.03, 0.02, -0.05;
  qd << 0.01, -0.02, 0.005, 0.1, -0.05, 0.2;
  Setpoint sp;
  sp.q_des << 0.1, 0, 0.4, 0, 0, 0;
  sp.qd_des << 0.01, 0, 0, 0, 0, 0;
  DynamicsTerms terms;
  const Vector6d f = NominalForce(c.platform, c.controller, q, qd, sp, &terms);
  const Vector6d u = PdAcceleration(c.controller, q, qd, sp);
  const Vector6d rhs = terms.M * u + terms.C_qd + terms.G;
  // The legs lose the viscous friction on the way (compensate_friction).
  ASSERT_GT(c.controller.leg_friction_nspm, 0.0);
  const Vector6d f_leg =
      f + LegViscousFriction(c.controller.leg_friction_nspm, terms.H.transpose() * qd);
  ASSERT_GT((f_leg - f).norm(), 1e-6);  // the state moves: friction matters here
  EXPECT_LT((terms.H * f_leg - rhs).norm(), 1e-9 * rhs.norm());
  // And the model, driven by the net leg force, accelerates by u.
  EXPECT_LT((ForwardDynamics(terms, f_leg) - u).norm(), 1e-9 * u.norm());
}

// Classic RK4 of the plant qdd = M^-1 (H (F - b H^T qd) - C qd - G), F held over the step.
void Rk4Step(const PlatformParams& p, double b, const Vector6d& f, double dt, Vector6d* q,
             Vector6d* qd) {
  auto accel = [&](const Vector6d& qa, const Vector6d& qda) {
    const DynamicsTerms t = EvaluateDynamics(p, qa, qda);
    return ForwardDynamics(t, f + LegViscousFriction(b, t.H.transpose() * qda));
  };
  const Vector6d k1q = *qd, k1v = accel(*q, *qd);
  const Vector6d k2q = *qd + 0.5 * dt * k1v, k2v = accel(*q + 0.5 * dt * k1q, k2q);
  const Vector6d k3q = *qd + 0.5 * dt * k2v, k3v = accel(*q + 0.5 * dt * k2q, k3q);
  const Vector6d k4q = *qd + dt * k3v, k4v = accel(*q + dt * k3q, k4q);
  *q += dt / 6.0 * (k1q + 2 * k2q + 2 * k3q + k4q);
  *qd += dt / 6.0 * (k1v + 2 * k2v + 2 * k3v + k4v);
}

TEST(ControlLaw, ClosedLoopConvergesToAReachableSetpoint) {
  const StackConfig& c = DefaultStackConfig();
  Vector6d q = c.home_pose, qd = Vector6d::Zero();
  Vector6d target;
  target << 0.05, -0.03, 0.45, 0.05, -0.03, 0.1;
  const Setpoint sp = Setpoint::HoldAt(target);
  const double dt = 1e-3;
  DynamicsTerms terms;
  double max_overshoot_m = 0.0;
  for (int k = 0; k < 4000; ++k) {  // 4 s, gains kp 25, kd 10: critically damped, w = 5/s
    const Vector6d f = NominalForce(c.platform, c.controller, q, qd, sp, &terms);
    ASSERT_TRUE(f.allFinite());
    Rk4Step(c.platform, c.actuators.viscous_friction_nspm, f, dt, &q, &qd);
    max_overshoot_m = std::max(max_overshoot_m, q(2) - target(2));
  }
  // Error ~ (1 + w t) e^{-w t} of 0.1 at 4 s: 4e-8 (plus the ZOH's small effect).
  EXPECT_LT((q - target).cwiseAbs().maxCoeff(), 1e-5);
  EXPECT_LT(qd.cwiseAbs().maxCoeff(), 1e-5);
  // Critical damping: no overshoot beyond the ZOH's effect.
  EXPECT_LT(max_overshoot_m, 1e-4);
}

}  // namespace
}  // namespace stewart
