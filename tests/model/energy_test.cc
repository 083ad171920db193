// Total energy is conserved when the only generalised forces are conservative:
// F = 0 (gravity only), and constant leg forces F (potential -F^T L(q)).
#include <gtest/gtest.h>

#include <random>

#include "stewart/model/dynamics.h"
#include "test_states.h"

namespace stewart {
namespace {

using test::DefaultConfig;

struct State {
  Vector6d q, qd;
};

// Leg forces from a potential: F = F0 - k (L(q) - L0), i.e. constant forces
// plus linear leg springs; V_F = -F0^T L + k/2 |L - L0|^2.
struct ConservativeLegForces {
  Vector6d F0 = Vector6d::Zero();
  double k_npm = 0.0;
  Vector6d L0 = Vector6d::Zero();
  Vector6d At(const Vector6d& L) const { return F0 - k_npm * (L - L0); }
  double Potential(const Vector6d& L) const {
    return -F0.dot(L) + 0.5 * k_npm * (L - L0).squaredNorm();
  }
};

State Derivative(const PlatformParams& p, const State& s, const ConservativeLegForces& f) {
  const DynamicsTerms t = EvaluateDynamics(p, s.q, s.qd);
  return {s.qd, ForwardDynamics(t, f.At(t.leg_length_m))};
}

State Rk4Step(const PlatformParams& p, const State& s, const ConservativeLegForces& F, double dt) {
  auto add = [](const State& a, const State& b, double k) {
    return State{a.q + k * b.q, a.qd + k * b.qd};
  };
  const State k1 = Derivative(p, s, F);
  const State k2 = Derivative(p, add(s, k1, dt / 2), F);
  const State k3 = Derivative(p, add(s, k2, dt / 2), F);
  const State k4 = Derivative(p, add(s, k3, dt), F);
  return State{s.q + dt / 6 * (k1.q + 2 * k2.q + 2 * k3.q + k4.q),
               s.qd + dt / 6 * (k1.qd + 2 * k2.qd + 2 * k3.qd + k4.qd)};
}

double TotalEnergy(const PlatformParams& p, const State& s, const ConservativeLegForces& F) {
  const DynamicsTerms t = EvaluateDynamics(p, s.q, s.qd);
  return KineticEnergy(t, s.qd) + PotentialEnergy(p, s.q) + F.Potential(t.leg_length_m);
}

// Holding forces plus leg springs: the platform swings about home for
// seconds, through every axis, while the total energy stays constant.
TEST(Energy, ConservedWithConservativeLegForces) {
  const auto& c = DefaultConfig();
  const auto& p = c.platform;
  const DynamicsTerms home = EvaluateDynamics(p, c.home_pose, Vector6d::Zero());
  ConservativeLegForces F_hold;
  F_hold.F0 = InverseDynamics(home, Vector6d::Zero());
  F_hold.k_npm = 500.0;
  F_hold.L0 = home.leg_length_m;
  std::mt19937 rng(20);
  std::uniform_real_distribution<double> v(-0.1, 0.1);
  for (int trial = 0; trial < 5; ++trial) {
    State s{c.home_pose, Vector6d::Zero()};
    for (int i = 0; i < 6; ++i) s.qd(i) = v(rng);
    const double e0 = TotalEnergy(p, s, F_hold);
    const double dt = 1e-4;
    double max_drift = 0.0;
    for (int k = 0; k < 30000; ++k) {  // 3 s
      s = Rk4Step(p, s, F_hold, dt);
      ASSERT_TRUE(PoseInWorkspace(p, s.q, 1.2)) << "left the workspace at t=" << k * dt;
      max_drift = std::max(max_drift, std::abs(TotalEnergy(p, s, F_hold) - e0));
    }
    EXPECT_LT(max_drift, 1e-9) << "trial " << trial;
  }
}

// F = 0: a ballistic flight (upward throw with spin) while inside the stroke.
TEST(Energy, ConservedWithZeroForce) {
  const auto& c = DefaultConfig();
  const auto& p = c.platform;
  std::mt19937 rng(21);
  std::uniform_real_distribution<double> w(-1.0, 1.0);
  for (int trial = 0; trial < 5; ++trial) {
    State s{c.home_pose, Vector6d::Zero()};
    s.qd << 0.1 * w(rng), 0.1 * w(rng), 0.6, w(rng), w(rng), w(rng);
    const ConservativeLegForces F;  // F = 0
    const double e0 = TotalEnergy(p, s, F);
    const double dt = 1e-4;
    double max_drift = 0.0;
    int steps = 0;
    for (; steps < 20000 && PoseInWorkspace(p, s.q, 1.2); ++steps) {
      s = Rk4Step(p, s, F, dt);
      max_drift = std::max(max_drift, std::abs(TotalEnergy(p, s, F) - e0));
    }
    EXPECT_GT(steps, 1000) << "flight too short to test anything";
    EXPECT_LT(max_drift, 1e-9) << "trial " << trial;
  }
}

}  // namespace
}  // namespace stewart
