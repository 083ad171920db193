#include "stewart/model/joint_tolerance.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "stewart/model/kinematics.h"
#include "stewart/model/rotation.h"
#include "test_states.h"

namespace stewart {
namespace {

using test::DefaultConfig;

// The tolerance of the bounds the stack is measured in (docs/campaign.md).
const JointTolerance kTolerance{0.001, 0.5 * M_PI / 180.0};

// One joint moved by a radius offset (m) and an angle offset (rad) on its
// circle, exactly (a rotation about z, not its first-order step).
Vector3d Moved(const Vector3d& joint_m, double radius_offset_m, double angle_offset_rad) {
  const double r = joint_m.head<2>().norm();
  const double angle = std::atan2(joint_m(1), joint_m(0)) + angle_offset_rad;
  return Vector3d((r + radius_offset_m) * std::cos(angle), (r + radius_offset_m) * std::sin(angle),
                  joint_m(2));
}

// Offsets per leg: base radius, base angle, platform radius, platform angle.
using JointOffsets = Eigen::Matrix<double, 4, kNumLegs>;

PlatformParams Displaced(const PlatformParams& nominal, const JointOffsets& offsets) {
  PlatformParams p = nominal;
  for (int i = 0; i < kNumLegs; ++i) {
    p.base_joints_in_B_m.col(i) =
        Moved(nominal.base_joints_in_B_m.col(i), offsets(0, i), offsets(1, i));
    p.platform_joints_in_P_m.col(i) =
        Moved(nominal.platform_joints_in_P_m.col(i), offsets(2, i), offsets(3, i));
  }
  return p;
}

// The pose the nominal geometry fits to the leg lengths of `truth` at q.
Vector6d FittedPose(const PlatformParams& nominal, const PlatformParams& truth, const Vector6d& q) {
  const ForwardKinematicsResult fit = ForwardKinematics(nominal, InverseKinematics(truth, q), q);
  EXPECT_TRUE(fit.converged);
  return fit.q;
}

std::vector<Vector6d> Poses() {
  const Vector6d home = DefaultConfig().home_pose;
  std::vector<Vector6d> poses(4, home);
  poses[1](0) = 0.11;                               // on the x limit
  poses[2].head<3>() << 0.11, 0.11, 0.51;           // a corner of the limits
  poses[3] << -0.05, 0.03, 0.45, 0.04, -0.03, 0.1;  // tilted and turned
  return poses;
}

TEST(JointTolerance, NoGeometryWithinTheToleranceMovesTheFittedPoseBeyondTheBound) {
  const PlatformParams& nominal = DefaultConfig().platform;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (const Vector6d& q : Poses()) {
    const Vector6d bound = PoseErrorBound(nominal, kTolerance, q);
    ASSERT_TRUE(bound.allFinite());
    ASSERT_GT(bound.head<3>().minCoeff(), 1e-4);  // a tolerance of a mm is felt
    Vector6d largest = Vector6d::Zero();
    for (int sample = 0; sample < 2000; ++sample) {
      JointOffsets offsets;
      for (int i = 0; i < kNumLegs; ++i) {
        offsets.col(i) << kTolerance.radius_m * unit(rng), kTolerance.angle_rad * unit(rng),
            kTolerance.radius_m * unit(rng), kTolerance.angle_rad * unit(rng);
      }
      const Vector6d error = FittedPose(nominal, Displaced(nominal, offsets), q) - q;
      largest = largest.cwiseMax(error.cwiseAbs());
    }
    std::printf(
        "[joint tolerance] q (%.2f %.2f %.2f): bound x %.2f y %.2f z %.2f mm, tilt %.2f %.2f "
        "mrad; largest of 2000 draws x %.2f y %.2f z %.2f mm, tilt %.2f %.2f mrad\n",
        q(0), q(1), q(2), 1e3 * bound(0), 1e3 * bound(1), 1e3 * bound(2), 1e3 * bound(3),
        1e3 * bound(4), 1e3 * largest(0), 1e3 * largest(1), 1e3 * largest(2), 1e3 * largest(3),
        1e3 * largest(4));
    // First order: the second-order terms are ~ (r angle)^2 / L, under 1 %.
    for (int a = 0; a < kNumAxes; ++a) {
      EXPECT_LE(largest(a), 1.01 * bound(a)) << "axis " << a << " at " << q.transpose();
    }
  }
}

// The bound is the worst case, not merely an upper bound: the geometry that
// moves each joint to its extreme with the sign that adds up on an axis
// moves the fitted pose by the bound.
TEST(JointTolerance, TheAdversarialGeometryReachesTheBound) {
  const PlatformParams& nominal = DefaultConfig().platform;
  for (const Vector6d& q : Poses()) {
    const Vector6d bound = PoseErrorBound(nominal, kTolerance, q);
    const LegGeometry legs = ComputeLegGeometry(nominal, q);
    const Matrix6d inverse = LegLengthJacobian(legs, q.tail<3>()).inverse();
    const Matrix3d R = RotationFromEuler(q.tail<3>());
    for (int a = 0; a < kNumAxes; ++a) {
      JointOffsets offsets;
      for (int i = 0; i < kNumLegs; ++i) {
        // dL_i = n^T (R dp_i - db_i): push L_i the way row a of J^-1 adds it.
        const double s = inverse(a, i) >= 0.0 ? 1.0 : -1.0;
        const Vector3d n = legs.unit_in_B.col(i);
        const Vector3d n_in_P = R.transpose() * n;
        const Vector3d b = nominal.base_joints_in_B_m.col(i);
        const Vector3d p = nominal.platform_joints_in_P_m.col(i);
        const Vector3d b_radial = Vector3d(b(0), b(1), 0).normalized();
        const Vector3d p_radial = Vector3d(p(0), p(1), 0).normalized();
        const Vector3d b_tangential(-b_radial(1), b_radial(0), 0);
        const Vector3d p_tangential(-p_radial(1), p_radial(0), 0);
        auto sign = [](double v) { return v >= 0.0 ? 1.0 : -1.0; };
        offsets.col(i) << -s * sign(n.dot(b_radial)) * kTolerance.radius_m,
            -s * sign(n.dot(b_tangential)) * kTolerance.angle_rad,
            s * sign(n_in_P.dot(p_radial)) * kTolerance.radius_m,
            s * sign(n_in_P.dot(p_tangential)) * kTolerance.angle_rad;
      }
      const Vector6d error = FittedPose(nominal, Displaced(nominal, offsets), q) - q;
      // Second-order terms leave up to ~3e-5 m, 3 % of the smallest (z) bound.
      EXPECT_NEAR(std::fabs(error(a)), bound(a), 0.03 * bound(a))
          << "axis " << a << " at " << q.transpose();
    }
  }
}

TEST(JointTolerance, AnExactGeometryHasNoError) {
  EXPECT_EQ(PoseErrorBound(DefaultConfig().platform, JointTolerance{}, DefaultConfig().home_pose),
            Vector6d::Zero());
}

}  // namespace
}  // namespace stewart
