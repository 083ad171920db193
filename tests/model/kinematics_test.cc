#include "stewart/model/kinematics.h"

#include <gtest/gtest.h>

#include <random>

#include "stewart/model/imu.h"
#include "stewart/model/rotation.h"
#include "test_states.h"

namespace stewart {
namespace {

using test::DefaultConfig;
using test::ForRandomPoses;
using test::RandomPose;

TEST(Rotation, EulerRoundTripAndRateMatrix) {
  ForRandomPoses(1, 200, [&](const Vector6d& q, std::mt19937*) {
    const Vector3d rpy = q.tail<3>();
    EXPECT_LT((EulerFromRotation(RotationFromEuler(rpy)) - rpy).norm(), 1e-12);
    // omega from finite differences of R: Rdot R^T = [omega]x
    const Vector3d rpyd(0.3, -0.2, 0.5);
    const double h = 1e-6;
    const Matrix3d Rdot =
        (RotationFromEuler(rpy + h * rpyd) - RotationFromEuler(rpy - h * rpyd)) / (2 * h);
    const Matrix3d W = Rdot * RotationFromEuler(rpy).transpose();
    const Vector3d omega_fd(W(2, 1), W(0, 2), W(1, 0));
    EXPECT_LT((EulerRateMatrix(rpy) * rpyd - omega_fd).norm(), 1e-8);
    // Edot rd by finite differences of E along rd
    const Vector3d bias_fd =
        (EulerRateMatrix(rpy + h * rpyd) - EulerRateMatrix(rpy - h * rpyd)) / (2 * h) * rpyd;
    EXPECT_LT((EulerRateBiasAcceleration(rpy, rpyd) - bias_fd).norm(), 1e-8);
  });
}

TEST(Kinematics, HomePoseLegsInsideStroke) {
  const auto& c = DefaultConfig();
  const Vector6d l = InverseKinematics(c.platform, c.home_pose);
  EXPECT_TRUE(LegLengthsWithinStroke(c.platform, l));
  // Symmetric design: every leg equally long at home.
  EXPECT_LT(l.maxCoeff() - l.minCoeff(), 1e-12);
}

TEST(Kinematics, PaperScenarioInsideStroke) {
  const auto& c = DefaultConfig();
  // Every setpoint of the paper's scenario and the limits themselves.
  for (double x : {-0.11, 0.0, 0.1, 0.11}) {
    for (double y : {-0.11, 0.0, 0.1, 0.11}) {
      for (double z : {0.39, 0.4, 0.45, 0.5, 0.51}) {
        Vector6d q;
        q << x, y, z, 0, 0, 0;
        EXPECT_TRUE(PoseInWorkspace(c.platform, q)) << q.transpose();
      }
    }
  }
}

TEST(Kinematics, ForwardOfInverseIsIdentity) {
  const auto& c = DefaultConfig();
  std::mt19937 rng(2);
  for (int n = 0; n < 1000; ++n) {
    const Vector6d q = RandomPose(&rng);
    const Vector6d l = InverseKinematics(c.platform, q);
    const ForwardKinematicsResult fk = ForwardKinematics(c.platform, l, c.home_pose);
    ASSERT_TRUE(fk.converged) << q.transpose();
    EXPECT_LT((fk.q - q).cwiseAbs().maxCoeff(), 1e-10) << q.transpose();
    EXPECT_LE(fk.iterations, 10);
  }
}

TEST(Kinematics, ForwardKinematicsReportsNonConvergence) {
  const auto& c = DefaultConfig();
  Vector6d impossible = Vector6d::Constant(10.0);  // no pose has 10 m legs here
  impossible(0) = 0.01;
  const ForwardKinematicsResult fk = ForwardKinematics(c.platform, impossible, c.home_pose);
  EXPECT_FALSE(fk.converged);
  Vector6d nan_lengths = InverseKinematics(c.platform, c.home_pose);
  nan_lengths(2) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(ForwardKinematics(c.platform, nan_lengths, c.home_pose).converged);
}

TEST(Kinematics, JacobianEqualsFiniteDifferences) {
  const auto& c = DefaultConfig();
  ForRandomPoses(3, 500, [&](const Vector6d& q, std::mt19937*) {
    const Matrix6d J = LegLengthJacobian(c.platform, q);
    Matrix6d J_fd;
    const double h = 1e-6;
    for (int j = 0; j < 6; ++j) {
      Vector6d dq = Vector6d::Zero();
      dq(j) = h;
      J_fd.col(j) =
          (InverseKinematics(c.platform, q + dq) - InverseKinematics(c.platform, q - dq)) / (2 * h);
    }
    EXPECT_LT((J - J_fd).cwiseAbs().maxCoeff(), 1e-8) << q.transpose();
  });
}

TEST(Kinematics, WorkspaceChecks) {
  const auto& c = DefaultConfig();
  Vector6d q = c.home_pose;
  EXPECT_TRUE(PoseInWorkspace(c.platform, q));
  q(2) = 0.9;  // legs beyond full extension
  EXPECT_FALSE(PoseInWorkspace(c.platform, q));
  q(2) = 0.2;  // legs shorter than fully retracted
  EXPECT_FALSE(PoseInWorkspace(c.platform, q));
  q = c.home_pose;
  q(4) = 1.5;  // near the Euler singularity
  EXPECT_FALSE(PoseInWorkspace(c.platform, q));
  q(4) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(PoseInWorkspace(c.platform, q));
}

}  // namespace
}  // namespace stewart

namespace stewart {
namespace {

// The IMU equations against finite differences of the pose.
TEST(Imu, GyroAndAccelerometerMatchFiniteDifferences) {
  std::mt19937 rng(4);
  const double g = 9.81;
  const Vector3d offset(0.01, -0.02, 0.03);
  for (int n = 0; n < 200; ++n) {
    const Vector6d q = test::RandomPose(&rng);
    const Vector6d qd = test::RandomVelocity(&rng);
    const Vector6d qdd = test::RandomVelocity(&rng);
    const double h = 1e-5;
    // Point position p(t) = t + R r, along the quadratic path q + qd t + qdd t^2/2.
    auto point = [&](double t) {
      const Vector6d qt = q + qd * t + 0.5 * qdd * t * t;
      return Vector3d(qt.head<3>() + RotationFromEuler(qt.tail<3>()) * offset);
    };
    const Vector3d a_fd = (point(h) - 2 * point(0) + point(-h)) / (h * h);
    const Matrix3d R = RotationFromEuler(q.tail<3>());
    const Vector3d expected_f = R.transpose() * (a_fd + Vector3d(0, 0, g));
    EXPECT_LT((ImuSpecificForce(q, qd, qdd, offset, g) - expected_f).norm(), 1e-4);
    const Matrix3d Rdot =
        (RotationFromEuler((q + h * qd).tail<3>()) - RotationFromEuler((q - h * qd).tail<3>())) /
        (2 * h);
    const Matrix3d W = R.transpose() * Rdot;  // [omega_P]x
    EXPECT_LT((BodyAngularVelocity(q, qd) - Vector3d(W(2, 1), W(0, 2), W(1, 0))).norm(), 1e-8);
  }
}

}  // namespace
}  // namespace stewart
