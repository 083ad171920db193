// Poses the platform cannot be in (pose_plausibility.h, docs/safety.md
// "Implausible poses"): rejected as invalid input with the safe stop's zero
// force, never filtered, whatever the variant.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "safety_test_support.h"
#include "stewart/model/kinematics.h"
#include "stewart/safety/pose_plausibility.h"

namespace stewart::safety::test {
namespace {

constexpr double kPi = 3.141592653589793;

struct Variant {
  SafetyVariant variant;
  bool force_limits;
  std::string Name() const { return ToString(variant) + (force_limits ? " force-limited" : ""); }
};
const Variant kVariants[] = {{SafetyVariant::kClosedForm, false},
                             {SafetyVariant::kClosedForm, true},
                             {SafetyVariant::kUncomposed, false},
                             {SafetyVariant::kUncomposed, true}};

// The answer to an implausible pose: the flagged safe stop with zero force
// (the hold brake would evaluate the model at that pose), and nothing
// non-finite in the diagnostics.
void ExpectRejected(SafetyFilter* filter, const Vector6d& q, const std::string& where) {
  const Vector6d qd = Vector6d::Constant(0.001);
  const Vector6d f_des = HoverForce(DefaultConfig().home_pose);
  SafetyDiagnostics d;
  const Vector6d f = filter->Step(q, qd, f_des, &d);
  EXPECT_EQ(f, Vector6d::Zero()) << where << "\nF* " << f.transpose();
  EXPECT_TRUE(d.flags & kFlagInvalidInput) << where;
  EXPECT_TRUE(d.flags & kFlagFallback) << where;
  EXPECT_FALSE(d.flags & kFlagInfeasible) << where;
  EXPECT_EQ(d.filter_case, FilterCase::kFallback) << where;
  EXPECT_EQ(d.mu_p, 0.0) << where;
  EXPECT_EQ(d.mu_v, 0.0) << where;
  EXPECT_TRUE(std::isfinite(d.correction_norm)) << where;
  // The watchdog's safe stop at the same state: zero force too.
  SafetyDiagnostics stop;
  EXPECT_EQ(filter->SafeStopCommand(q, qd, &stop), Vector6d::Zero()) << where;
}

TEST(DegeneratePose, HugeAnglesAreInvalidInput) {
  for (const Variant& v : kVariants) {
    SafetyFilter filter = MakeRichFilter(v.force_limits, v.variant);
    for (int axis = 3; axis < 6; ++axis) {
      for (const double angle : {1e300, -1e300, 1e20, 2 * kPi + 0.01, -2 * kPi - 0.01}) {
        Vector6d q = DefaultConfig().home_pose;
        q(axis) = angle;
        ExpectRejected(&filter, q,
                       v.Name() + " q(" + std::to_string(axis) + ") = " + std::to_string(angle));
      }
    }
  }
}

// At and near theta = pi the platform is upside down: not a pose, and the
// model there gave the un-composed variant +-2.8e14 N flagged only "active".
TEST(DegeneratePose, UpsideDownIsInvalidInputAtAndNearPi) {
  for (const Variant& v : kVariants) {
    SafetyFilter filter = MakeRichFilter(v.force_limits, v.variant);
    for (const double theta : {kPi, kPi - 1e-9, kPi + 1e-9, kPi - 1e-3, -kPi, kPi / 2,
                               kPi / 2 - 1e-9, 2.0, kMaxTiltRad + 1e-9}) {
      for (const int axis : {3, 4}) {
        Vector6d q = DefaultConfig().home_pose;
        q(axis) = theta;
        ExpectRejected(&filter, q,
                       v.Name() + " q(" + std::to_string(axis) + ") = " + std::to_string(theta));
      }
    }
  }
}

// psi = pi/2 at home height: every leg inside its stroke, H singular.
TEST(DegeneratePose, SingularYawIsInvalidInput) {
  const PlatformParams& p = DefaultConfig().platform;
  for (const double psi : {kPi / 2, kPi / 2 - 1e-6, -kPi / 2, kMaxYawRad + 1e-9}) {
    Vector6d q = DefaultConfig().home_pose;
    q(5) = psi;
    ASSERT_EQ(PoseProblems(p, q, InverseKinematics(p, q)), kPoseYawBeyondBound);
    for (const Variant& v : kVariants) {
      SafetyFilter filter = MakeRichFilter(v.force_limits, v.variant);
      ExpectRejected(&filter, q, v.Name() + " psi = " + std::to_string(psi));
    }
  }
}

// A singular H at a pose inside every bound (the terms given to
// StepWithTerms): the solves with H detect it (kMaxLegJacobianCondition),
// invalid input and zero force, wherever the step needs H.
TEST(DegeneratePose, SingularLegJacobianIsInvalidInputWhereTheStepSolvesWithIt) {
  const Vector6d q = DefaultConfig().home_pose;
  const Vector6d qd = Vector6d::Constant(0.001);
  DynamicsTerms t = EvaluateDynamics(DefaultConfig().platform, q, qd);
  const Vector6d f_des = InverseDynamics(t, Vector6d::Unit(0) * 20.0);  // the filter must act
  t.H.col(5) = t.H.col(4) * (1.0 + 1e-12);  // two legs along one line of force
  for (const Variant& v : kVariants) {
    SafetyConfig config = RichSafetyConfig();
    config.variant = v.variant;
    config.force_limits_enabled = v.force_limits;
    config.correction_metric = CorrectionMetric::kAcceleration;
    SafetyFilter filter(DefaultConfig().platform, config, DefaultConfig().actuators);
    SafetyDiagnostics d;
    const Vector6d f = filter.StepWithTerms(t, q, qd, f_des, &d);
    EXPECT_EQ(f, Vector6d::Zero()) << v.Name() << "\nF* " << f.transpose();
    EXPECT_TRUE(d.flags & kFlagInvalidInput) << v.Name();
    EXPECT_TRUE(d.flags & kFlagFallback) << v.Name();
    EXPECT_FALSE(d.flags & kFlagInfeasible) << v.Name();
  }
}

TEST(DegeneratePose, BelowTheBaseIsInvalidInput) {
  // Mirrored through the base plane every leg has its home length: only
  // z <= 0 tells this pose from home.
  Vector6d q = DefaultConfig().home_pose;
  q(2) = -q(2);
  const PlatformParams& p = DefaultConfig().platform;
  ASSERT_LE((InverseKinematics(p, q) - InverseKinematics(p, DefaultConfig().home_pose))
                .cwiseAbs()
                .maxCoeff(),
            1e-12);
  EXPECT_EQ(PoseProblems(p, q, InverseKinematics(p, q)), kPoseBelowBase);
  for (const Variant& v : kVariants) {
    SafetyFilter filter = MakeRichFilter(v.force_limits, v.variant);
    ExpectRejected(&filter, q, v.Name() + " below the base");
  }
}

// Home pose raised along z until the longest leg is `excess_m` beyond the
// stroke's upper end.
Vector6d RaisedUntilLongestLegExceedsStroke(double excess_m) {
  const PlatformParams& p = DefaultConfig().platform;
  double lo = DefaultConfig().home_pose(2), hi = lo + 1.0;
  Vector6d q = DefaultConfig().home_pose;
  for (int i = 0; i < 200; ++i) {
    q(2) = 0.5 * (lo + hi);
    (InverseKinematics(p, q).maxCoeff() - p.leg_max_length_m > excess_m ? hi : lo) = q(2);
  }
  return q;
}

TEST(DegeneratePose, LegsBeyondTheStrokeAreInvalidInput) {
  const PlatformParams& p = DefaultConfig().platform;
  for (const Variant& v : kVariants) {
    SafetyFilter filter = MakeRichFilter(v.force_limits, v.variant);
    for (const double excess_m : {kLegStrokeToleranceM + 1e-4, 0.05, 10.0}) {
      const Vector6d q = RaisedUntilLongestLegExceedsStroke(excess_m);
      ASSERT_EQ(PoseProblems(p, q, InverseKinematics(p, q)), kPoseLegOutsideStroke);
      ExpectRejected(&filter, q, v.Name() + " leg " + std::to_string(excess_m) + " m out");
    }
    // Shorter than the stroke's lower end.
    Vector6d q = DefaultConfig().home_pose;
    double lo = 0.0, hi = q(2);
    for (int i = 0; i < 200; ++i) {
      q(2) = 0.5 * (lo + hi);
      (InverseKinematics(p, q).minCoeff() < p.leg_min_length_m - 0.02 ? lo : hi) = q(2);
    }
    ASSERT_EQ(PoseProblems(p, q, InverseKinematics(p, q)), kPoseLegOutsideStroke);
    ExpectRejected(&filter, q, v.Name() + " leg below the stroke");
  }
}

// Within the tolerance (an estimate at an end stop, with noise) the state is
// still a pose: filtered, not rejected.
TEST(DegeneratePose, LegsWithinTheToleranceAreFiltered) {
  const Vector6d q = RaisedUntilLongestLegExceedsStroke(0.5 * kLegStrokeToleranceM);
  for (const Variant& v : kVariants) {
    SafetyFilter filter = MakeRichFilter(v.force_limits, v.variant);
    SafetyDiagnostics d;
    const Vector6d f = filter.Step(q, Vector6d::Constant(0.001), HoverForce(q), &d);
    EXPECT_TRUE(f.allFinite()) << v.Name();
    EXPECT_FALSE(d.flags & kFlagInvalidInput) << v.Name();
    EXPECT_NE(d.filter_case, FilterCase::kFallback) << v.Name();
  }
}

TEST(DegeneratePose, EveryPoseOfTheRandomSweepsIsPlausible) {
  const PlatformParams& p = DefaultConfig().platform;
  std::mt19937 rng(3);
  for (int n = 0; n < 10000; ++n) {
    const Vector6d q = RandomPoseInLimits(&rng);
    ASSERT_EQ(PoseProblems(p, q, InverseKinematics(p, q)), kPosePlausible) << q.transpose();
  }
  EXPECT_EQ(
      PoseProblems(p, DefaultConfig().home_pose, InverseKinematics(p, DefaultConfig().home_pose)),
      kPosePlausible);
}

TEST(DegeneratePose, NonFiniteLegLengthIsOutsideTheStroke) {
  const PlatformParams& p = DefaultConfig().platform;
  Vector6d l = InverseKinematics(p, DefaultConfig().home_pose);
  l(2) = NAN;
  EXPECT_EQ(PoseProblems(p, DefaultConfig().home_pose, l), kPoseLegOutsideStroke);
}

}  // namespace
}  // namespace stewart::safety::test
