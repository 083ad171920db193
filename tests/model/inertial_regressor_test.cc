// The inertial regressor against the model: for random states and random
// platform bodies (mass, CoM, full inertia tensor), Y pi plus the legs' part
// equals M qdd + C qd + G of EvaluateDynamics, and the momentum form
// (Y_p, Y_r) equals M qd and C qd + G - Mdot qd.
#include "stewart/model/inertial_regressor.h"

#include <gtest/gtest.h>

#include <random>

#include "stewart/model/dynamics.h"
#include "stewart/model/rotation.h"
#include "test_states.h"

namespace stewart {
namespace {

// A rigid body that could exist: a box of random edges, turned by a random
// rotation, at a random CoM.
PlatformParams RandomPlatformBody(std::mt19937* rng) {
  std::uniform_real_distribution<double> mass(0.2, 2.0), edge(0.02, 0.4), com(-0.08, 0.08),
      angle(-3.0, 3.0);
  PlatformParams p = test::DefaultConfig().platform;
  const double m = mass(*rng);
  const Vector3d e(edge(*rng), edge(*rng), edge(*rng));
  const Vector3d principal = m / 12.0 *
                             Vector3d(e.y() * e.y() + e.z() * e.z(), e.x() * e.x() + e.z() * e.z(),
                                      e.x() * e.x() + e.y() * e.y());
  const Matrix3d R = RotationFromEuler(Vector3d(angle(*rng), angle(*rng) / 3.0, angle(*rng)));
  const Matrix3d I = R * principal.asDiagonal() * R.transpose();
  p.platform_mass_kg = m;
  p.platform_com_in_P_m = Vector3d(com(*rng), com(*rng), com(*rng));
  p.platform_inertia_kgm2 = I.diagonal();
  p.platform_inertia_products_kgm2 = Vector3d(I(0, 1), I(0, 2), I(1, 2));
  return p;
}

Vector6d RandomAcceleration(std::mt19937* rng) {
  std::uniform_real_distribution<double> lin(-3.0, 3.0), ang(-10.0, 10.0);
  Vector6d qdd;
  qdd << lin(*rng), lin(*rng), lin(*rng), ang(*rng), ang(*rng), ang(*rng);
  return qdd;
}

TEST(InertialRegressor, EqualsTheModelsDynamics) {
  test::ForRandomPoses(41, 500, [](const Vector6d& q, std::mt19937* rng) {
    const PlatformParams p = RandomPlatformBody(rng);
    const Vector6d qd = test::RandomVelocity(rng);
    const Vector6d qdd = RandomAcceleration(rng);
    const DynamicsTerms t = EvaluateDynamics(p, q, qd);
    const Vector6d model = t.M * qdd + t.C_qd + t.G;
    const Vector6d regression =
        PlatformInertialRegressor(p.gravity_mps2, q, qd, qdd) * InertialParametersOf(p) +
        LegDynamicsForce(p, q, qd, qdd);
    ASSERT_LT((regression - model).norm(), 1e-9 * (1.0 + model.norm()))
        << "q " << q.transpose() << "\nmodel " << model.transpose() << "\nregression "
        << regression.transpose();
  });
}

TEST(InertialRegressor, SeesEveryParameter) {
  // A regressor with a column missing would pass the test above only if that
  // column never mattered: each parameter changes the force at some state.
  const PlatformParams p = test::DefaultConfig().platform;
  std::mt19937 rng(3);
  InertialRegressor largest = InertialRegressor::Zero();
  for (int n = 0; n < 50; ++n) {
    const Vector6d q = test::RandomPose(&rng);
    const InertialRegressor Y = PlatformInertialRegressor(
        p.gravity_mps2, q, test::RandomVelocity(&rng), RandomAcceleration(&rng));
    largest = largest.cwiseMax(Y.cwiseAbs());
  }
  for (int j = 0; j < kNumInertialParameters; ++j) {
    EXPECT_GT(largest.col(j).maxCoeff(), 0.1) << "parameter " << j;
  }
}

TEST(InertialRegressor, MomentumFormEqualsTheModel) {
  test::ForRandomPoses(42, 300, [](const Vector6d& q, std::mt19937* rng) {
    const PlatformParams p = RandomPlatformBody(rng);
    const Vector6d qd = test::RandomVelocity(rng);
    const InertialParameters pi = InertialParametersOf(p);
    const DynamicsTerms t = EvaluateDynamics(p, q, qd);
    const LegMomentumTerms legs = LegMomentum(p, q, qd);

    const Vector6d momentum = MomentumRegressor(q, qd) * pi + legs.momentum;
    ASSERT_LT((momentum - t.M * qd).norm(), 1e-12 * (1.0 + (t.M * qd).norm()));

    // Mdot qd of the whole model by a 5-point stencil along qd.
    const double h = 1e-4;
    auto M_at = [&](double s) { return EvaluateDynamics(p, q + s * qd, qd).M; };
    const Matrix6d Mdot =
        (M_at(-2 * h) - 8.0 * M_at(-h) + 8.0 * M_at(h) - M_at(2 * h)) / (12.0 * h);
    const Vector6d remainder_model = t.C_qd + t.G - Mdot * qd;
    const Vector6d remainder =
        MomentumRemainderRegressor(p.gravity_mps2, q, qd) * pi + legs.remainder;
    ASSERT_LT((remainder - remainder_model).norm(), 1e-8 * (1.0 + remainder_model.norm()))
        << "model " << remainder_model.transpose() << "\nregression " << remainder.transpose();
  });
}

TEST(InertialRegressor, MomentumFormIntegratesTheDynamics) {
  // Along a smooth motion, Y pi = d/dt (Y_p pi) + Y_r pi: the derivative of the
  // momentum regressor (central difference in time) plus the remainder.
  const PlatformParams p = test::DefaultConfig().platform;
  std::mt19937 rng(7);
  const InertialParameters pi = InertialParametersOf(RandomPlatformBody(&rng));
  const Vector6d q0 = test::RandomPose(&rng), v = test::RandomVelocity(&rng),
                 a = RandomAcceleration(&rng);
  auto q_at = [&](double t) {
    Vector6d q = q0 + t * v + 0.5 * t * t * a;
    return q;
  };
  auto qd_at = [&](double t) {
    Vector6d qd = v + t * a;
    return qd;
  };
  const double t = 0.01, h = 1e-5;
  const Vector6d dp = (MomentumRegressor(q_at(t + h), qd_at(t + h)) -
                       MomentumRegressor(q_at(t - h), qd_at(t - h))) *
                      pi / (2.0 * h);
  const Vector6d lhs = PlatformInertialRegressor(p.gravity_mps2, q_at(t), qd_at(t), a) * pi;
  const Vector6d rhs = dp + MomentumRemainderRegressor(p.gravity_mps2, q_at(t), qd_at(t)) * pi;
  EXPECT_LT((lhs - rhs).norm(), 1e-7 * (1.0 + lhs.norm()));
}

TEST(InertialRegressor, ParametersRoundTrip) {
  std::mt19937 rng(9);
  for (int n = 0; n < 100; ++n) {
    const PlatformParams p = RandomPlatformBody(&rng);
    const PlatformBody body = PlatformBodyOf(InertialParametersOf(p));
    EXPECT_NEAR(body.mass_kg, p.platform_mass_kg, 1e-15);
    EXPECT_LT((body.com_in_P_m - p.platform_com_in_P_m).norm(), 1e-15);
    EXPECT_LT((body.inertia_about_com_in_P_kgm2 - PlatformInertiaInP(p)).norm(), 1e-15);
    const PlatformParams back = WithPlatformBody(test::DefaultConfig().platform, body);
    EXPECT_LT((PlatformInertiaInP(back) - PlatformInertiaInP(p)).norm(), 1e-15);
  }
}

TEST(Rotation, EulerRateMatrixDerivativeTimesRateIsTheBiasAcceleration) {
  std::mt19937 rng(11);
  for (int n = 0; n < 100; ++n) {
    const Vector6d q = test::RandomPose(&rng), qd = test::RandomVelocity(&rng);
    const EulerAngleTrig trig(Vector3d(q.tail<3>()));
    const Vector3d rd = qd.tail<3>();
    EXPECT_LT(
        (EulerRateMatrixDerivative(trig, rd) * rd - EulerRateBiasAcceleration(trig, rd)).norm(),
        1e-14);
    // And it is the time derivative of E.
    const double h = 1e-6;
    const Matrix3d dE = (EulerRateMatrix(Vector3d(q.tail<3>() + h * rd)) -
                         EulerRateMatrix(Vector3d(q.tail<3>() - h * rd))) /
                        (2.0 * h);
    EXPECT_LT((dE - EulerRateMatrixDerivative(trig, rd)).norm(), 1e-8);
  }
}

}  // namespace
}  // namespace stewart
