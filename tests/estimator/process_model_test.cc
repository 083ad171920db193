// The EKF's analytic dqdd/dq and dqdd/dqd (estimator/process_model.h) against
// central differences of the terms they cover: H (F - b H^T qd) - G for dq
// (the inertial part -M^-1 d(M qdd + C qd)/dq is left out by design,
// docs/estimator.md) and the friction term for dqd; and qdd itself against
// DynamicsAcceleration.
#include <gtest/gtest.h>

#include <random>

#include "stewart/config/config_loader.h"
#include "stewart/estimator/process_model.h"
#include "stewart/model/dynamics.h"

namespace stewart {
namespace {

TEST(ProcessModel, AnalyticJacobiansMatchFiniteDifferencesOfTheTermsTheyCover) {
  const StackConfig c = LoadStackConfig(DefaultConfigPath());
  const double b = c.actuators.viscous_friction_nspm;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 16; ++trial) {
    Vector6d q = c.home_pose, qd, f;
    for (int i = 0; i < 3; ++i) {
      q(i) += 0.05 * u(rng);
      q(3 + i) += 0.2 * u(rng);
      qd(i) = 0.1 * u(rng);
      qd(3 + i) = 1.0 * u(rng);
    }
    for (int i = 0; i < 6; ++i) f(i) = 1.5 + 2.0 * u(rng);
    Vector6d qdd;
    Matrix6d dqdd_dq, dqdd_dqd;
    DynamicsAccelerationJacobians(c.platform, b, q, qd, f, &qdd, &dqdd_dq, &dqdd_dqd);
    EXPECT_LT((qdd - DynamicsAcceleration(c.platform, b, q, qd, f)).norm(), 1e-9 * qdd.norm() + 1e-12);

    const DynamicsTerms t0 = EvaluateDynamics(c.platform, q, qd);
    auto covered = [&](const DynamicsTerms& t) {
      return Vector6d(t.H * (f - b * t.H.transpose() * qd) - t.G);
    };
    Matrix6d d_covered;
    constexpr double kStep = 1e-5;
    for (int k = 0; k < 6; ++k) {
      Vector6d qp = q, qm = q;
      qp(k) += kStep;
      qm(k) -= kStep;
      d_covered.col(k) = (covered(EvaluateDynamics(c.platform, qp, qd)) -
                          covered(EvaluateDynamics(c.platform, qm, qd))) /
                         (2.0 * kStep);
    }
    const Matrix6d expected_dq = t0.M.llt().solve(d_covered);
    EXPECT_LT((dqdd_dq - expected_dq).norm(), 1e-6 * expected_dq.norm()) << "trial " << trial;
    const Matrix6d expected_dqd = -b * t0.M.llt().solve(t0.H * t0.H.transpose());
    EXPECT_LT((dqdd_dqd - expected_dqd).norm(), 1e-9 * expected_dqd.norm()) << "trial " << trial;
  }
}

}  // namespace
}  // namespace stewart
