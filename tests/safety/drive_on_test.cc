// The hold the supervisor's ARMING starts from (SafetyFilter::DriveOnCommand):
// the model's hold with d_z shifted towards the z velocity limit by what the
// limit cannot absorb within safety.drive_on_response_s,
//   shift = max(0, k sigma_z - m_z (zd_max - zd) / T),  m_z = 1 / (M^-1)_zz.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <cmath>
#include <cstdio>

#include "safety_test_support.h"
#include "stewart/model/dynamics.h"

namespace stewart::safety::test {
namespace {

constexpr double kZdMaxMps = 0.010;  // the shipped z velocity limit

GeneralizedDisturbance Uncertain(double std_z_n) {
  GeneralizedDisturbance d;
  d.force_n << 0.1, -0.2, 0.3, 0.01, 0.0, -0.01;
  d.std_n << 2.0, 2.0, std_z_n, 0.2, 0.2, 0.2;
  return d;
}

double EffectiveVerticalMassKg(const StackConfig& c, const Vector6d& q, const Vector6d& qd) {
  const DynamicsTerms terms = EvaluateDynamics(c.platform, q, qd);
  return 1.0 / terms.M.ldlt().solve(Vector6d::Unit(2))(2);
}

TEST(DriveOn, TheHoldLiftsByTheShiftLessThanTheModelsHold) {
  const StackConfig& c = DefaultConfig();
  SafetyFilter filter(c.platform, c.safety, c.actuators);
  const Vector6d q = c.home_pose;
  Vector6d qd = Vector6d::Zero();
  qd(2) = 0.002;
  const GeneralizedDisturbance d = Uncertain(2.0);
  const double expected = c.safety.disturbance_sigma * 2.0 - EffectiveVerticalMassKg(c, q, qd) *
                                                                 (kZdMaxMps - qd(2)) /
                                                                 c.safety.drive_on_response_s;
  std::printf("[drive-on] at home, zd 2 mm/s: shift %.3f N of k sigma_z %.1f N (m_z %.3f kg)\n",
              expected, c.safety.disturbance_sigma * 2.0, EffectiveVerticalMassKg(c, q, qd));
  ASSERT_GT(expected, 0.5);  // the shipped numbers leave a shift to test
  EXPECT_NEAR(filter.DriveOnShiftN(q, qd, d), expected, 1e-9);
  SafetyDiagnostics hold_diag, drive_on_diag;
  const Vector6d hold = filter.SafeStopCommand(q, qd, d, &hold_diag);
  const Vector6d drive_on = filter.DriveOnCommand(q, qd, d, &drive_on_diag);
  // H (F_hold - F_drive_on) is the shift along z and nothing else.
  const DynamicsTerms terms = EvaluateDynamics(c.platform, q, qd);
  const Vector6d generalised = terms.H * (hold - drive_on);
  EXPECT_NEAR(generalised(2), expected, 1e-9);
  EXPECT_LT(generalised.cwiseAbs().maxCoeff() - std::abs(generalised(2)), 1e-9);
  EXPECT_TRUE(drive_on_diag.flags & kFlagFallback);
}

TEST(DriveOn, NoShiftOnceTheEstimateHasSeenThePlatformMove) {
  const StackConfig& c = DefaultConfig();
  SafetyFilter filter(c.platform, c.safety, c.actuators);
  const Vector6d q = c.home_pose;
  const GeneralizedDisturbance d = Uncertain(0.05);  // sigma_z after one sample of motion
  EXPECT_EQ(filter.DriveOnShiftN(q, Vector6d::Zero(), d), 0.0);
  SafetyDiagnostics a, b;
  EXPECT_EQ(filter.DriveOnCommand(q, Vector6d::Zero(), d, &a),
            filter.SafeStopCommand(q, Vector6d::Zero(), d, &b));
}

TEST(DriveOn, ALiftAnsweredAtOnceOrAzWithoutOneSidedLimitsGetsNoShift) {
  const StackConfig& c = DefaultConfig();
  const GeneralizedDisturbance d = Uncertain(2.0);
  const Vector6d q = c.home_pose;
  const Vector6d qd = Vector6d::Zero();
  SafetyConfig at_once = c.safety;
  at_once.drive_on_response_s = 0.0;
  EXPECT_EQ(SafetyFilter(c.platform, at_once, c.actuators).DriveOnShiftN(q, qd, d), 0.0);
  SafetyConfig both_sides = c.safety;
  for (VelocityLimitConfig& v : both_sides.velocity_limits) {
    if (v.axis == 2) v.lower = -0.01;
  }
  EXPECT_EQ(SafetyFilter(c.platform, both_sides, c.actuators).DriveOnShiftN(q, qd, d), 0.0);
  SafetyConfig no_d = c.safety;
  no_d.use_disturbance_estimate = false;
  EXPECT_EQ(SafetyFilter(c.platform, no_d, c.actuators).DriveOnShiftN(q, qd, d), 0.0);
}

TEST(DriveOn, ALowerLimitOnlyShiftsTheOtherWay) {
  const StackConfig& c = DefaultConfig();
  SafetyConfig lower = c.safety;
  for (VelocityLimitConfig& v : lower.velocity_limits) {
    if (v.axis == 2) {
      v.lower = -0.01;
      v.upper.reset();
    }
  }
  SafetyFilter filter(c.platform, lower, c.actuators);
  const GeneralizedDisturbance d = Uncertain(2.0);
  SafetyFilter shipped(c.platform, c.safety, c.actuators);
  const Vector6d q = c.home_pose;
  EXPECT_NEAR(filter.DriveOnShiftN(q, Vector6d::Zero(), d),
              -shipped.DriveOnShiftN(q, Vector6d::Zero(), d), 1e-12);
  EXPECT_LT(filter.DriveOnShiftN(q, Vector6d::Zero(), d), 0.0);
}

TEST(DriveOn, ANonFiniteUncertaintyOrStateGetsNoShift) {
  const StackConfig& c = DefaultConfig();
  SafetyFilter filter(c.platform, c.safety, c.actuators);
  GeneralizedDisturbance d = Uncertain(2.0);
  d.std_n(2) = NAN;
  EXPECT_EQ(filter.DriveOnShiftN(c.home_pose, Vector6d::Zero(), d), 0.0);
  Vector6d qd = Vector6d::Zero();
  qd(0) = NAN;
  EXPECT_EQ(filter.DriveOnShiftN(c.home_pose, qd, Uncertain(2.0)), 0.0);
}

}  // namespace
}  // namespace stewart::safety::test
