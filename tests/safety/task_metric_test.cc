// The task-acceleration metric keeps a velocity barrier's correction on the
// barrier's axis where the kinetic-energy metric spreads it over the axes
// M couples (docs/safety.md, "Correction metric").
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "safety_test_support.h"
#include "stewart/config/default_config.h"
#include "stewart/model/dc_motor.h"

namespace stewart::safety::test {
namespace {

// The P-16P legs (rotors in M) off centre in y, cruising in x below its
// velocity limit, the nominal accelerating further along x: only xd's
// barrier acts. Returns the change of qdd the filter makes.
Vector6d CorrectionOfTheAcceleration(CorrectionMetric metric) {
  const StackConfig& c = DcMotorStackConfig();
  SafetyConfig s = c.safety;
  s.correction_metric = metric;
  s.force_limits_enabled = false;  // the metric alone
  const SafetyFilter filter(c.platform, s, c.actuators);
  Vector6d q = c.home_pose;
  q(1) = -0.08;
  Vector6d qd = Vector6d::Zero();
  qd(0) = 0.012;  // 3 mm/s below xd's limit (15 mm/s): one period's step is 0.5 mm/s
  const DynamicsTerms terms = EvaluateDynamics(c.platform, q, qd);
  Vector6d qdd_des = Vector6d::Zero();
  qdd_des(0) = 0.5;
  // The drive that gives qdd_des against the motors' back-EMF damping.
  const Vector6d leg_speed_mps = terms.H.transpose() * qd;
  const Vector6d f_des = InverseDynamics(terms, qdd_des) -
                         LegViscousFriction(ModelLegDampingNspm(c.actuators), leg_speed_mps);
  SafetyDiagnostics d;
  const Vector6d f = filter.StepWithTerms(terms, q, qd, f_des, &d);
  EXPECT_TRUE(f.allFinite());
  EXPECT_FALSE(d.infeasible);
  EXPECT_GT(d.mu_v, 0.0) << "xd's barrier must act";
  EXPECT_EQ(d.mu_p, 0.0) << "far from every position limit";
  return ForwardDynamics(terms, f) - ForwardDynamics(terms, f_des);
}

TEST(TaskAccelerationMetric, AVelocityCorrectionStaysOnItsAxis) {
  const Vector6d kinetic = CorrectionOfTheAcceleration(CorrectionMetric::kAcceleration);
  const Vector6d task = CorrectionOfTheAcceleration(CorrectionMetric::kTaskAcceleration);
  for (const Vector6d* v : {&kinetic, &task}) {
    std::printf("[task metric] dqdd %s: [%.4g %.4g %.4g %.4g %.4g %.4g]\n",
                v == &kinetic ? "kinetic" : "task   ", (*v)(0), (*v)(1), (*v)(2), (*v)(3), (*v)(4),
                (*v)(5));
  }
  // Both brake x.
  EXPECT_LT(kinetic(0), 0.0);
  EXPECT_LT(task(0), 0.0);
  // The other axes: what the rotors' coupling in M moves in the kinetic
  // metric, (nearly) nothing in the task metric (the composed barrier's
  // other velocity terms have weights of rounding size here).
  const double kinetic_off_axis = kinetic.tail<5>().norm() / std::fabs(kinetic(0));
  const double task_off_axis = task.tail<5>().norm() / std::fabs(task(0));
  EXPECT_GT(kinetic_off_axis, 0.1);
  EXPECT_LT(task_off_axis, 1e-6);
}

}  // namespace
}  // namespace stewart::safety::test
