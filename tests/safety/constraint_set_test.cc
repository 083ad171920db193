#include "stewart/safety/constraint_set.h"

#include <gtest/gtest.h>

#include <stdexcept>

#include "safety_test_support.h"
#include "stewart/model/joint_tolerance.h"
#include "stewart/model/kinematics.h"

namespace stewart::safety::test {
namespace {

TEST(ConstraintSet, DefaultConfigIsThePapersUpperLimitsAndTheLegStrokes) {
  const ConstraintSet c = BuildConstraintSet(DefaultConfig().platform, DefaultConfig().safety);
  // x, y, z upper, then a lower and an upper stroke barrier per leg.
  EXPECT_EQ(c.num_position, 3 + 2 * kNumLegs);
  EXPECT_EQ(c.position[3].source, PositionSource::kLegLength);
  // The three velocity limits, then one recovery barrier per position limit
  // (the axes', then the legs').
  EXPECT_EQ(c.num_velocity, 6 + 2 * kNumLegs);
  EXPECT_EQ(c.position[2].name, "z_upper");
  EXPECT_EQ(c.velocity[2].name, "zd_upper");
  EXPECT_EQ(c.velocity[2].alpha_v, 2.0);
  EXPECT_EQ(c.velocity[2].recovery_of, -1);
  EXPECT_EQ(c.velocity[5].name, "z_upper_recovery");
  EXPECT_EQ(c.velocity[5].recovery_of, 2);
  EXPECT_EQ(c.velocity[5].index, 2);
  EXPECT_EQ(c.velocity[5].sign, -1.0);
  EXPECT_EQ(c.velocity[5].source, PositionSource::kAxis);
  EXPECT_TRUE(c.has_recovery);
  // Leg 0's lower stroke barrier (position 3) and its recovery barrier: the
  // speed back is half the slowest translational limit (zd's 0.010 m/s).
  EXPECT_EQ(c.velocity[6].name, "leg0_lower_recovery");
  EXPECT_EQ(c.velocity[6].source, PositionSource::kLegLength);
  EXPECT_EQ(c.velocity[6].index, 0);
  EXPECT_EQ(c.velocity[6].recovery_of, 3);
  EXPECT_EQ(c.velocity[6].sign, 1.0);
  EXPECT_DOUBLE_EQ(c.velocity[6].recovery_speed, 0.005);
  EXPECT_EQ(c.velocity[17].name, "leg5_upper_recovery");
  EXPECT_TRUE(c.has_leg_recovery);
}

TEST(ConstraintSet, TheLegsRecoveryCanBeLeftOut) {
  SafetyConfig s = DefaultConfig().safety;
  s.leg_stroke.recovery = false;
  const ConstraintSet c = BuildConstraintSet(DefaultConfig().platform, s);
  EXPECT_EQ(c.num_velocity, 6);
  EXPECT_TRUE(c.has_recovery);
  EXPECT_FALSE(c.has_leg_recovery);
}

// a_i = dh_v,i/dqd: sign e_j for an axis, sign J_l(i,:)^T for a leg.
TEST(ConstraintSet, AVelocityBarriersGradientIsItsRatesGradient) {
  const StackConfig& config = DefaultConfig();
  const ConstraintSet c = BuildConstraintSet(config.platform, config.safety);
  Vector6d q = config.home_pose;
  q(0) += 0.02;
  q(4) += 0.05;
  const Matrix6d j_l = LegLengthJacobian(config.platform, q);
  const Matrix6d h = j_l.transpose();
  EXPECT_EQ(VelocityBarrierGradient(c.velocity[5], h), -Vector6d::Unit(2));
  EXPECT_EQ(VelocityBarrierGradient(c.velocity[6], h), Vector6d(j_l.row(0).transpose()));
  EXPECT_EQ(VelocityBarrierGradient(c.velocity[17], h), Vector6d(-j_l.row(5).transpose()));
}

TEST(ConstraintSet, RecoveryGainZeroLeavesTheRecoveryBarriersOut) {
  SafetyConfig s = DefaultConfig().safety;
  s.recovery_gain_per_s = 0.0;
  const ConstraintSet c = BuildConstraintSet(DefaultConfig().platform, s);
  EXPECT_EQ(c.num_velocity, 3);
  EXPECT_FALSE(c.has_recovery);
  EXPECT_FALSE(c.has_leg_recovery);
}

TEST(ConstraintSet, RichConfigHasEveryKind) {
  const ConstraintSet c = BuildConstraintSet(DefaultConfig().platform, RichSafetyConfig());
  EXPECT_EQ(c.num_position, 8 + 12);
  // 8 velocity limits and a recovery barrier per axis limit and per leg limit.
  EXPECT_EQ(c.num_velocity, 8 + 8 + 12);
  EXPECT_EQ(c.position[0].name, "x_lower");
  EXPECT_EQ(c.position[8].name, "leg0_lower");
  EXPECT_EQ(c.position[8].source, PositionSource::kLegLength);
  EXPECT_DOUBLE_EQ(c.position[9].limit, DefaultConfig().platform.leg_max_length_m - 0.005);
}

TEST(ConstraintSet, TheJointToleranceDrawsTheAxisLimitsInByThePoseErrorsWorstCase) {
  const StackConfig& config = DefaultConfig();
  SafetyConfig s = config.safety;
  s.joint_radius_tolerance_m = 0.001;
  s.joint_angle_tolerance_rad = 0.5 * M_PI / 180.0;
  const ConstraintSet c = BuildConstraintSet(config.platform, s);
  const JointTolerance tolerance{0.001, 0.5 * M_PI / 180.0};
  // The worst pose error on the x limit face is at least the bound there.
  Vector6d on_x_limit = config.home_pose;
  on_x_limit(0) = 0.11;
  const Vector6d there = PoseErrorBound(config.platform, tolerance, on_x_limit);
  EXPECT_GE(c.joint_tolerance_margin(0), there(0));
  // Millimetres: the shipped tolerance's figures (docs/safety.md).
  EXPECT_GT(c.joint_tolerance_margin(0), 0.004);
  EXPECT_LT(c.joint_tolerance_margin(0), 0.008);
  EXPECT_GT(c.joint_tolerance_margin(2), 0.0005);
  EXPECT_LT(c.joint_tolerance_margin(2), 0.003);
  ASSERT_EQ(c.position[0].name, "x_upper");
  EXPECT_DOUBLE_EQ(c.position[0].limit, 0.11 - c.joint_tolerance_margin(0));
  EXPECT_DOUBLE_EQ(c.position[2].limit, 0.51 - c.joint_tolerance_margin(2));
  // The legs' stroke is measured directly: no margin.
  EXPECT_DOUBLE_EQ(c.position[4].limit, config.platform.leg_max_length_m - 0.005);

  s.joint_radius_tolerance_m = 0.0;
  s.joint_angle_tolerance_rad = 0.0;
  const ConstraintSet exact = BuildConstraintSet(config.platform, s);
  EXPECT_EQ(exact.joint_tolerance_margin, Vector6d::Zero());
  EXPECT_DOUBLE_EQ(exact.position[0].limit, 0.11);
}

TEST(ConstraintSet, AToleranceThatDrawsALimitPastHomeNamesItsKey) {
  SafetyConfig s = DefaultConfig().safety;
  s.joint_radius_tolerance_m = 0.05;
  try {
    BuildConstraintSet(DefaultConfig().platform, s);
    FAIL() << "accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("safety.joint_position_tolerance"), std::string::npos)
        << e.what();
  }
}

TEST(ConstraintSet, TooManyLimitsAreRejected) {
  SafetyConfig s = RichSafetyConfig();
  for (int i = 0; i < 3; ++i)
    s.position_limits.insert(s.position_limits.end(), s.position_limits.begin(),
                             s.position_limits.begin() + 4);
  EXPECT_THROW(BuildConstraintSet(DefaultConfig().platform, s), std::invalid_argument);
}

TEST(ConstraintSet, QpVariantNeedsAReferenceSolver) {
  SafetyConfig s = RichSafetyConfig();
  s.variant = SafetyVariant::kQpReference;
  EXPECT_THROW(SafetyFilter(DefaultConfig().platform, s, DefaultConfig().actuators),
               std::invalid_argument);
}

}  // namespace
}  // namespace stewart::safety::test
