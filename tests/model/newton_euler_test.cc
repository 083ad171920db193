// With massless legs the model must equal the Newton-Euler equations of the
// platform alone under six forces F_i n_i at its joints.
#include <gtest/gtest.h>

#include <random>

#include "stewart/model/dynamics.h"
#include "stewart/model/rotation.h"
#include "test_states.h"

namespace stewart {
namespace {

TEST(NewtonEuler, MasslessLegsEqualRigidPlatform) {
  PlatformParams p = test::DefaultConfig().platform;
  p.leg = LegParams{};  // massless legs
  std::mt19937 rng(30);
  std::uniform_real_distribution<double> force(-30.0, 30.0);
  for (int n = 0; n < 500; ++n) {
    const Vector6d q = test::RandomPose(&rng);
    const Vector6d qd = test::RandomVelocity(&rng);
    Vector6d F;
    for (int i = 0; i < 6; ++i) F(i) = force(rng);
    const Vector6d qdd = ForwardDynamics(EvaluateDynamics(p, q, qd), F);

    // Independent Newton-Euler, in {B}.
    const Vector3d rpy = q.tail<3>(), rpyd = qd.tail<3>(), rpydd = qdd.tail<3>();
    const Matrix3d R = RotationFromEuler(rpy);
    const Matrix3d E = EulerRateMatrix(rpy);
    const Vector3d omega = E * rpyd;
    const Vector3d alpha = E * rpydd + EulerRateBiasAcceleration(rpy, rpyd);
    const Vector3d c = R * p.platform_com_in_P_m;
    const Vector3d a_com = qdd.head<3>() + alpha.cross(c) + omega.cross(omega.cross(c));
    const LegGeometry legs = ComputeLegGeometry(p, q);
    Vector3d force_sum = Vector3d(0, 0, -p.gravity_mps2 * p.platform_mass_kg);
    Vector3d moment_about_com = Vector3d::Zero();
    for (int i = 0; i < 6; ++i) {
      const Vector3d f = F(i) * legs.unit_in_B.col(i);
      force_sum += f;
      moment_about_com += (legs.platform_offset_in_B_m.col(i) - c).cross(f);
    }
    const Matrix3d I = R * p.platform_inertia_kgm2.asDiagonal() * R.transpose();
    EXPECT_LT((p.platform_mass_kg * a_com - force_sum).norm(), 1e-9);
    EXPECT_LT((I * alpha + omega.cross(I * omega) - moment_about_com).norm(), 1e-9);
  }
}

}  // namespace
}  // namespace stewart
