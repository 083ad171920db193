// The controller state machine: workspace rejection, invalid states, time
// from utime, scenario following.
#include "stewart/controller/controller.h"

#include <gtest/gtest.h>

#include <limits>

#include "stewart/config/default_config.h"
#include "stewart/config/scenario_loader.h"

namespace stewart {
namespace {

Controller Live() {
  return Controller(DefaultStackConfig().platform, DefaultStackConfig().controller,
                    DefaultStackConfig().home_pose);
}

Setpoint At(double x, double y, double z) {
  Vector6d q;
  q << x, y, z, 0, 0, 0;
  return Setpoint::HoldAt(q);
}

// The gravity-holding force at `pose`: what F_des must be at rest there.
Vector6d HoldForce(const Vector6d& pose) {
  DynamicsTerms terms;
  return NominalForce(DefaultStackConfig().platform, DefaultStackConfig().controller, pose,
                      Vector6d::Zero(), Setpoint::HoldAt(pose), &terms);
}

TEST(Controller, HoldsHomeUntilASetpointArrives) {
  Controller c = Live();
  ControllerOutput out;
  ASSERT_EQ(c.Step(1000, DefaultStackConfig().home_pose, Vector6d::Zero(), &out), StepStatus::kOk);
  EXPECT_EQ(out.setpoint.q_des, DefaultStackConfig().home_pose);
  EXPECT_FALSE(out.setpoint_rejected);
  EXPECT_LT((out.force_n - HoldForce(DefaultStackConfig().home_pose)).norm(), 1e-12);
}

TEST(Controller, RejectsSetpointsOutsideTheWorkspace) {
  Controller c = Live();
  ControllerOutput out;
  // Far above the stroke: legs would need > l_max.
  EXPECT_EQ(c.OfferSetpoint(At(0, 0, 1.5)), SetpointStatus::kOutsideWorkspace);
  ASSERT_EQ(c.Step(1000, DefaultStackConfig().home_pose, Vector6d::Zero(), &out), StepStatus::kOk);
  EXPECT_TRUE(out.setpoint_rejected);
  EXPECT_EQ(out.setpoint.q_des, DefaultStackConfig().home_pose);  // none valid yet: home

  EXPECT_EQ(c.OfferSetpoint(At(0.05, 0, 0.42)), SetpointStatus::kAccepted);
  ASSERT_EQ(c.Step(2000, DefaultStackConfig().home_pose, Vector6d::Zero(), &out), StepStatus::kOk);
  EXPECT_FALSE(out.setpoint_rejected);
  EXPECT_DOUBLE_EQ(out.setpoint.q_des(0), 0.05);

  // Below the base, and NaN: the last valid setpoint stays.
  EXPECT_EQ(c.OfferSetpoint(At(0.0, 0, -0.1)), SetpointStatus::kOutsideWorkspace);
  Setpoint nan = At(0, 0, 0.4);
  nan.qd_des(3) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(c.OfferSetpoint(nan), SetpointStatus::kNonFinite);
  ASSERT_EQ(c.Step(3000, DefaultStackConfig().home_pose, Vector6d::Zero(), &out), StepStatus::kOk);
  EXPECT_TRUE(out.setpoint_rejected);
  EXPECT_DOUBLE_EQ(out.setpoint.q_des(0), 0.05);
  EXPECT_DOUBLE_EQ(out.setpoint.q_des(2), 0.42);
  EXPECT_TRUE(out.force_n.allFinite());
}

TEST(Controller, RejectsInvalidStatesWithoutOutput) {
  Controller c = Live();
  ControllerOutput out;
  out.force_n.setConstant(123.0);
  Vector6d q = DefaultStackConfig().home_pose;
  q(4) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(c.Step(1000, q, Vector6d::Zero(), &out), StepStatus::kNonFiniteState);
  Vector6d qd = Vector6d::Zero();
  qd(0) = std::numeric_limits<double>::infinity();
  EXPECT_EQ(c.Step(1000, DefaultStackConfig().home_pose, qd, &out), StepStatus::kNonFiniteState);
  EXPECT_TRUE((out.force_n.array() == 123.0).all());  // untouched

  ASSERT_EQ(c.Step(5000, DefaultStackConfig().home_pose, Vector6d::Zero(), &out), StepStatus::kOk);
  EXPECT_EQ(c.Step(5000, DefaultStackConfig().home_pose, Vector6d::Zero(), &out),
            StepStatus::kTimeNotIncreasing);
  EXPECT_EQ(c.Step(4000, DefaultStackConfig().home_pose, Vector6d::Zero(), &out),
            StepStatus::kTimeNotIncreasing);
}

TEST(Controller, FollowsAScenarioOnStateTime) {
  const Scenario s = ParseScenario(
      "name: t\nduration_s: 2\nsegments:\n"
      "  - {start_s: 0, type: step, q_des: [0.02, 0, 0.4, 0, 0, 0]}\n"
      "  - {start_s: 1, type: step, q_des: [0, 0, 2.0, 0, 0, 0]}\n"  // outside: rejected
      "  - {start_s: 1.5, type: step, q_des: [0, 0.03, 0.41, 0, 0, 0]}\n");
  Controller c(DefaultStackConfig().platform, DefaultStackConfig().controller,
               DefaultStackConfig().home_pose, s);
  ASSERT_TRUE(c.following_scenario());
  ControllerOutput out;
  const int64_t t0 = 1'700'000'000'000'000;  // time is relative to the first state
  ASSERT_EQ(c.Step(t0, DefaultStackConfig().home_pose, Vector6d::Zero(), &out), StepStatus::kOk);
  EXPECT_DOUBLE_EQ(out.setpoint.q_des(0), 0.02);
  EXPECT_DOUBLE_EQ(out.scenario_time_s, 0.0);
  ASSERT_EQ(c.Step(t0 + 999'999, DefaultStackConfig().home_pose, Vector6d::Zero(), &out),
            StepStatus::kOk);
  EXPECT_DOUBLE_EQ(out.setpoint.q_des(0), 0.02);
  EXPECT_FALSE(out.scenario_rejection.has_value());

  ASSERT_EQ(c.Step(t0 + 1'000'000, DefaultStackConfig().home_pose, Vector6d::Zero(), &out),
            StepStatus::kOk);
  ASSERT_TRUE(out.scenario_rejection.has_value());
  EXPECT_EQ(*out.scenario_rejection, SetpointStatus::kOutsideWorkspace);
  EXPECT_TRUE(out.setpoint_rejected);
  EXPECT_DOUBLE_EQ(out.setpoint.q_des(0), 0.02);  // the last valid one is held
  EXPECT_FALSE(c.scenario_finished());

  ASSERT_EQ(c.Step(t0 + 1'600'000, DefaultStackConfig().home_pose, Vector6d::Zero(), &out),
            StepStatus::kOk);
  EXPECT_FALSE(out.setpoint_rejected);
  EXPECT_DOUBLE_EQ(out.setpoint.q_des(1), 0.03);
  EXPECT_FALSE(c.scenario_finished());
  ASSERT_EQ(c.Step(t0 + 2'000'000, DefaultStackConfig().home_pose, Vector6d::Zero(), &out),
            StepStatus::kOk);
  EXPECT_TRUE(c.scenario_finished());

  // Live setpoints do not steer a scenario.
  EXPECT_EQ(c.OfferSetpoint(At(0.05, 0, 0.4)), SetpointStatus::kAccepted);
  ASSERT_EQ(c.Step(t0 + 2'100'000, DefaultStackConfig().home_pose, Vector6d::Zero(), &out),
            StepStatus::kOk);
  EXPECT_DOUBLE_EQ(out.setpoint.q_des(1), 0.03);
  EXPECT_DOUBLE_EQ(out.setpoint.q_des(0), 0.0);
}

}  // namespace
}  // namespace stewart
