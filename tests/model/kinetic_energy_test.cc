// M itself against the model's definition: 1/2 qd^T M qd must equal the
// kinetic energy of the seven bodies computed from their positions alone
// (velocities by central differences of the geometry along qd). The other
// dynamics tests check C qd against M and G against V, but a consistent
// Lagrangian of a different model (a lost inertia term, say) would pass them.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "stewart/model/dynamics.h"
#include "stewart/model/kinematics.h"
#include "stewart/model/rotation.h"
#include "test_states.h"

namespace stewart {
namespace {

// Positions of everything that carries kinetic energy, from q alone.
struct BodyPositions {
  Vector3d platform_com;  // {B}
  Matrix3d R;
  Eigen::Matrix<double, 3, kNumLegs> unit;     // n_i
  Eigen::Matrix<double, 3, kNumLegs> rod_com;  // a_i - e2 n_i
  Vector6d leg_length_m;
};

BodyPositions PositionsAt(const PlatformParams& p, const Vector6d& q) {
  BodyPositions b;
  b.R = RotationFromEuler(q.tail<3>());
  b.platform_com = q.head<3>() + b.R * p.platform_com_in_P_m;
  const LegGeometry legs = ComputeLegGeometry(p, q);
  b.unit = legs.unit_in_B;
  b.leg_length_m = legs.length_m;
  for (int i = 0; i < kNumLegs; ++i) {
    const Vector3d a = q.head<3>() + legs.platform_offset_in_B_m.col(i);
    b.rod_com.col(i) = a - p.leg.rod_com_from_platform_m * legs.unit_in_B.col(i);
  }
  return b;
}

// docs/model.md: platform 1/2 m |v_c|^2 + 1/2 omega^T R I R^T omega; per leg
// the cylinder 1/2 m1 |e1 nd|^2 + 1/2 I1 |n x nd|^2 and the rod
// 1/2 m2 |v_rod|^2 + 1/2 I2 |n x nd|^2 (no spin about the leg axis).
double KineticEnergyFromBodies(const PlatformParams& p, const Vector6d& q, const Vector6d& qd) {
  const double h = 1e-6;
  const BodyPositions plus = PositionsAt(p, q + h * qd);
  const BodyPositions minus = PositionsAt(p, q - h * qd);
  const BodyPositions at = PositionsAt(p, q);
  const Vector3d v_c = (plus.platform_com - minus.platform_com) / (2 * h);
  const Matrix3d W = (plus.R - minus.R) / (2 * h) * at.R.transpose();  // [omega]x
  const Vector3d omega(W(2, 1), W(0, 2), W(1, 0));
  const Vector3d omega_p = at.R.transpose() * omega;
  double energy = 0.5 * p.platform_mass_kg * v_c.squaredNorm() +
                  0.5 * omega_p.dot(p.platform_inertia_kgm2.asDiagonal() * omega_p);
  const LegParams& leg = p.leg;
  for (int i = 0; i < kNumLegs; ++i) {
    const Vector3d n = at.unit.col(i);
    const Vector3d nd = (plus.unit.col(i) - minus.unit.col(i)) / (2 * h);
    const Vector3d v_rod = (plus.rod_com.col(i) - minus.rod_com.col(i)) / (2 * h);
    const double leg_spin_sq = n.cross(nd).squaredNorm();
    energy += 0.5 * leg.cylinder_mass_kg * (leg.cylinder_com_from_base_m * nd).squaredNorm() +
              0.5 * leg.cylinder_inertia_kgm2 * leg_spin_sq;
    energy +=
        0.5 * leg.rod_mass_kg * v_rod.squaredNorm() + 0.5 * leg.rod_inertia_kgm2 * leg_spin_sq;
    const double leg_speed = (plus.leg_length_m(i) - minus.leg_length_m(i)) / (2 * h);
    energy += 0.5 * leg.actuator_reflected_mass_kg * leg_speed * leg_speed;  // rotor
  }
  return energy;
}

// The platform with DC-motor legs' rotor inertia (the default config's
// 80 kg reflected per leg, or less).
PlatformParams WithRotors(PlatformParams p, double reflected_mass_kg = 80.0) {
  p.leg.actuator_reflected_mass_kg = reflected_mass_kg;
  return p;
}

TEST(Dynamics, KineticEnergyMatchesBodyVelocities) {
  for (const PlatformParams& p :
       {test::DefaultConfig().platform, WithRotors(test::DefaultConfig().platform)}) {
    test::ForRandomPoses(16, 500, [&](const Vector6d& q, std::mt19937* rng) {
      const Vector6d qd = test::RandomVelocity(rng);
      const double expected = KineticEnergyFromBodies(p, q, qd);
      const double model = KineticEnergy(EvaluateDynamics(p, q, qd), qd);
      // Central differences at h = 1e-6: truncation ~1e-12, round-off ~1e-10
      // relative; a wrong mass or inertia term is a relative error >= 1e-4.
      EXPECT_NEAR(model, expected, 1e-8 * expected) << q.transpose();
    });
  }
}

// Every term counts: dropping any one mass parameter must change the energy
// by far more than the tolerance above, so the test would see it.
TEST(Dynamics, KineticEnergyTestSeesEveryMassParameter) {
  // A light rotor: 80 kg would outweigh the smallest terms below the bound.
  const PlatformParams p = WithRotors(test::DefaultConfig().platform, 0.5);
  std::mt19937 rng(17);
  const Vector6d q = test::RandomPose(&rng);
  const Vector6d qd = test::RandomVelocity(&rng);
  const double full = KineticEnergy(EvaluateDynamics(p, q, qd), qd);
  std::vector<PlatformParams> reduced(8, p);
  reduced[0].platform_mass_kg = 0.0;
  reduced[1].platform_inertia_kgm2.setZero();
  reduced[2].leg.cylinder_mass_kg = 0.0;
  reduced[3].leg.cylinder_inertia_kgm2 = 0.0;
  reduced[4].leg.rod_mass_kg = 0.0;
  reduced[5].leg.rod_inertia_kgm2 = 0.0;
  reduced[6].leg.rod_com_from_platform_m = 0.0;
  reduced[7].leg.actuator_reflected_mass_kg = 0.0;
  for (size_t k = 0; k < reduced.size(); ++k) {
    const double e = KineticEnergy(EvaluateDynamics(reduced[k], q, qd), qd);
    EXPECT_GT(std::abs(full - e), 1e-4 * full) << "parameter " << k;
    EXPECT_NEAR(e, KineticEnergyFromBodies(reduced[k], q, qd), 1e-8 * full) << "parameter " << k;
  }
}

}  // namespace
}  // namespace stewart
