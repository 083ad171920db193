#include "stewart/model/dynamics.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <random>
#include <vector>

#include "test_states.h"

namespace stewart {
namespace {

using test::DefaultConfig;
using test::ForRandomPoses;
using test::RandomPose;
using test::RandomVelocity;

constexpr int kStates = 500;

TEST(Dynamics, MassMatrixSymmetricPositiveDefinite) {
  const auto& p = DefaultConfig().platform;
  std::mt19937 rng(10);
  for (int n = 0; n < kStates; ++n) {
    const DynamicsTerms t = EvaluateDynamics(p, RandomPose(&rng), RandomVelocity(&rng));
    EXPECT_LT((t.M - t.M.transpose()).cwiseAbs().maxCoeff(), 1e-14);
    const Eigen::SelfAdjointEigenSolver<Matrix6d> eig(t.M);
    EXPECT_GT(eig.eigenvalues().minCoeff(), 1e-5);
  }
}

TEST(Dynamics, HIsTransposedLegJacobian) {
  const auto& p = DefaultConfig().platform;
  ForRandomPoses(11, kStates, [&](const Vector6d& q, std::mt19937* rng) {
    const DynamicsTerms t = EvaluateDynamics(p, q, RandomVelocity(rng));
    EXPECT_LT((t.H - LegLengthJacobian(p, q).transpose()).cwiseAbs().maxCoeff(), 1e-14);
  });
}

// Ldd = J_l qdd + J_l-dot qd: with qdd = 0 along q(t) = q + t qd (so the Euler
// rates stay qd), the legs' acceleration is the derivative of J_l(q(t)) qd,
// here a central difference.
TEST(Dynamics, LegBiasAccelerationIsTheLegJacobiansRate) {
  const auto& p = DefaultConfig().platform;
  ForRandomPoses(12, kStates, [&](const Vector6d& q, std::mt19937* rng) {
    const Vector6d qd = RandomVelocity(rng);
    const DynamicsTerms t = EvaluateDynamics(p, q, qd);
    constexpr double kStep = 1e-5;
    const Vector6d ahead = LegLengthJacobian(p, q + kStep * qd) * qd;
    const Vector6d behind = LegLengthJacobian(p, q - kStep * qd) * qd;
    const Vector6d expected = (ahead - behind) / (2.0 * kStep);
    EXPECT_LT((t.leg_bias_accel_mps2 - expected).cwiseAbs().maxCoeff(),
              1e-7 * (1.0 + expected.cwiseAbs().maxCoeff()));
  });
}

// Bit for bit: plant_sim's root functions take the leg lengths of the last
// model evaluation in place of InverseKinematics at the same q.
TEST(Dynamics, LegLengthsAreExactlyInverseKinematics) {
  const auto& p = DefaultConfig().platform;
  ForRandomPoses(18, kStates, [&](const Vector6d& q, std::mt19937* rng) {
    const DynamicsTerms t = EvaluateDynamics(p, q, RandomVelocity(rng));
    for (int i = 0; i < kNumLegs; ++i) EXPECT_EQ(t.leg_length_m(i), InverseKinematics(p, q)(i));
  });
}

Matrix6d MassMatrix(const PlatformParams& p, const Vector6d& q) {
  return EvaluateDynamics(p, q, Vector6d::Zero()).M;
}

// dM/dt along qd by a five-point stencil (truncation O(h^4), round-off
// ~eps/h): accurate to ~1e-11, far below what the tests resolve.
Matrix6d MassMatrixRate(const PlatformParams& p, const Vector6d& q, const Vector6d& qd) {
  const double h = 1e-4;
  return (-MassMatrix(p, q + 2 * h * qd) + 8 * MassMatrix(p, q + h * qd) -
          8 * MassMatrix(p, q - h * qd) + MassMatrix(p, q - 2 * h * qd)) /
         (12 * h);
}

// qd^T (Mdot - 2C) qd = 0, Mdot by central differences along qd. The
// energy-based CBF's derivative is only right if this holds.
// Also with the DC-motor legs' rotor inertia (80 kg reflected per leg).
std::vector<PlatformParams> ModelsUnderTest() {
  PlatformParams with_rotors = DefaultConfig().platform;
  with_rotors.leg.actuator_reflected_mass_kg = 80.0;
  return {DefaultConfig().platform, with_rotors};
}

TEST(Dynamics, PowerBalance) {
  for (const PlatformParams& p : ModelsUnderTest()) {
    ForRandomPoses(12, kStates, [&](const Vector6d& q, std::mt19937* rng) {
      const Vector6d qd = RandomVelocity(rng);
      const Matrix6d Mdot = MassMatrixRate(p, q, qd);
      const DynamicsTerms t = EvaluateDynamics(p, q, qd);
      const double scale = std::abs(qd.dot(Mdot * qd)) + 2 * std::abs(qd.dot(t.C_qd)) + 1e-12;
      EXPECT_LT(std::abs(qd.dot(Mdot * qd) - 2.0 * qd.dot(t.C_qd)) / scale, 1e-7);
    });
  }
}

// The whole vector, not only its power: C qd = Mdot qd - 1/2 d/dq (qd^T M qd)
// (Lagrange's equations).
TEST(Dynamics, CoriolisVectorMatchesLagrangian) {
  for (const PlatformParams& p : ModelsUnderTest()) {
    ForRandomPoses(13, kStates, [&](const Vector6d& q, std::mt19937* rng) {
      const Vector6d qd = RandomVelocity(rng);
      const double h = 1e-6;
      const Matrix6d Mdot = MassMatrixRate(p, q, qd);
      Vector6d dT_dq;
      for (int j = 0; j < 6; ++j) {
        Vector6d dq = Vector6d::Zero();
        dq(j) = h;
        dT_dq(j) = 0.5 * (qd.dot(MassMatrix(p, q + dq) * qd) - qd.dot(MassMatrix(p, q - dq) * qd)) /
                   (2 * h);
      }
      const Vector6d expected = Mdot * qd - dT_dq;
      const DynamicsTerms t = EvaluateDynamics(p, q, qd);
      EXPECT_LT((t.C_qd - expected).norm(), 1e-7 * (1.0 + expected.norm())) << q.transpose();
    });
  }
}

TEST(Dynamics, GravityIsGradientOfPotential) {
  const auto& p = DefaultConfig().platform;
  ForRandomPoses(14, kStates, [&](const Vector6d& q, std::mt19937*) {
    Vector6d grad;
    const double h = 1e-6;
    for (int j = 0; j < 6; ++j) {
      Vector6d dq = Vector6d::Zero();
      dq(j) = h;
      grad(j) = (PotentialEnergy(p, q + dq) - PotentialEnergy(p, q - dq)) / (2 * h);
    }
    const DynamicsTerms t = EvaluateDynamics(p, q, Vector6d::Zero());
    EXPECT_LT((t.G - grad).norm(), 1e-7);
  });
}

TEST(Dynamics, InverseOfForwardReturnsForce) {
  const auto& p = DefaultConfig().platform;
  std::mt19937 rng(15);
  std::uniform_real_distribution<double> force(-50.0, 50.0);
  for (int n = 0; n < kStates; ++n) {
    const DynamicsTerms t = EvaluateDynamics(p, RandomPose(&rng), RandomVelocity(&rng));
    Vector6d F;
    for (int i = 0; i < 6; ++i) F(i) = force(rng);
    const Vector6d qdd = ForwardDynamics(t, F);
    EXPECT_LT((InverseDynamics(t, qdd) - F).cwiseAbs().maxCoeff(), 1e-9);
  }
}

TEST(Dynamics, GravityCompensationHoldsHomePose) {
  const auto& c = DefaultConfig();
  const DynamicsTerms t = EvaluateDynamics(c.platform, c.home_pose, Vector6d::Zero());
  const Vector6d F_hold = InverseDynamics(t, Vector6d::Zero());
  // Legs push up, equally by symmetry, and carry the whole weight.
  EXPECT_GT(F_hold.minCoeff(), 0.0);
  EXPECT_LT(F_hold.maxCoeff() - F_hold.minCoeff(), 1e-9);
  EXPECT_LT(ForwardDynamics(t, F_hold).norm(), 1e-12);
  const auto& leg = c.platform.leg;
  const double total_weight =
      c.platform.gravity_mps2 *
      (c.platform.platform_mass_kg + 6 * (leg.cylinder_mass_kg + leg.rod_mass_kg));
  // Vertical leg-force sum is less than the total weight: the base joints
  // carry part of each leg's own weight.
  const double vertical = (t.H.row(2) * F_hold)(0);
  EXPECT_GT(vertical, c.platform.gravity_mps2 * c.platform.platform_mass_kg);
  EXPECT_LT(vertical, total_weight);
}

}  // namespace
}  // namespace stewart
