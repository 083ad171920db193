// psi_p, psi_v and g_p, g_v checked against an independent computation:
// Psi_c(F) = d/dt h_c + h_c, with d/dt h_c a central time difference of the
// composed barrier along the trajectory that the real model's forward
// dynamics gives for F (so it also checks the power-balance identity the
// energy barrier relies on), and g = dPsi/dF by finite differences.
#include <gtest/gtest.h>

#include <cmath>

#include "safety_test_support.h"
#include "stewart/safety/barriers.h"

namespace stewart::safety::test {
namespace {

// Central time difference over 1e-5 s: truncation dt^2/6 * d3h/dt3 with
// d3h/dt3 ~ k^2 |dh/dt|^3 ~ 50^2 * 10^3 (k = 50, rates ~10/s) gives ~4e-5
// absolute; relative to psi ~1..10 that is ~1e-5.
constexpr double kFdTol = 2e-5;

struct Composed {
  double h_pos, h_vel;
};

Composed ComposedAt(const ConstraintSet& c, const Vector6d& q, const Vector6d& qd) {
  const DynamicsTerms terms = EvaluateDynamics(DefaultConfig().platform, q, qd);
  BarrierEvaluation e;
  EvaluateBarriers(c, q, qd, terms, Vector6d::Zero(), &e);  // h does not depend on F
  return {e.h_pos, e.h_vel};
}

// Psi_p(F), Psi_v(F) from the trajectory: no use of g or of the formulas.
std::pair<double, double> PsiFromTrajectory(const ConstraintSet& c, const Vector6d& q,
                                            const Vector6d& qd, const Vector6d& f) {
  const DynamicsTerms terms = EvaluateDynamics(DefaultConfig().platform, q, qd);
  const Vector6d qdd = ForwardDynamics(terms, f);
  const double dt = 1e-5;
  const Composed plus = ComposedAt(c, q + qd * dt + 0.5 * qdd * dt * dt, qd + qdd * dt);
  const Composed minus = ComposedAt(c, q - qd * dt + 0.5 * qdd * dt * dt, qd - qdd * dt);
  const Composed now = ComposedAt(c, q, qd);
  return {(plus.h_pos - minus.h_pos) / (2 * dt) + now.h_pos,
          (plus.h_vel - minus.h_vel) / (2 * dt) + now.h_vel};
}

TEST(BarrierGradient, PsiAndGMatchTheModelsForwardDynamics) {
  SafetyConfig config = RichSafetyConfig();
  // Moderate sharpness so the composed barrier is smooth on the scale of the
  // time step (the formulas do not depend on k).
  config.k_position = 50.0;
  config.k_velocity = 50.0;
  const ConstraintSet c = BuildConstraintSet(DefaultConfig().platform, config);
  std::mt19937 rng(17);
  for (int n = 0; n < 60; ++n) {
    const Vector6d q = RandomPoseInLimits(&rng);
    const Vector6d qd = RandomVelocity(&rng) * 10.0;  // non-trivial power terms
    const DynamicsTerms terms = EvaluateDynamics(DefaultConfig().platform, q, qd);
    const Vector6d f_des = RandomNominalForce(terms, &rng);
    BarrierEvaluation e;
    EvaluateBarriers(c, q, qd, terms, f_des, &e);

    const auto [psi_p, psi_v] = PsiFromTrajectory(c, q, qd, f_des);
    EXPECT_NEAR(e.psi_p, psi_p, kFdTol * (1.0 + std::fabs(psi_p))) << "sample " << n;
    EXPECT_NEAR(e.psi_v, psi_v, kFdTol * (1.0 + std::fabs(psi_v))) << "sample " << n;

    Vector6d g_p_fd, g_v_fd;
    for (int i = 0; i < 6; ++i) {
      const double eps = 0.5;  // N; Psi is affine in F
      const Vector6d step = Vector6d::Unit(i) * eps;
      const auto [pp, vp] = PsiFromTrajectory(c, q, qd, f_des + step);
      const auto [pm, vm] = PsiFromTrajectory(c, q, qd, f_des - step);
      g_p_fd(i) = (pp - pm) / (2 * eps);
      g_v_fd(i) = (vp - vm) / (2 * eps);
    }
    EXPECT_LE((e.g_p - g_p_fd).norm(), kFdTol * (e.g_p.norm() + 1e-3)) << "sample " << n;
    EXPECT_LE((e.g_v - g_v_fd).norm(), kFdTol * e.g_v.norm()) << "sample " << n;
  }
}

TEST(BarrierGradient, PositionNormalIsMinusHTransposeQdAtRest) {
  const ConstraintSet c = BuildConstraintSet(DefaultConfig().platform, RichSafetyConfig());
  const Vector6d q = DefaultConfig().home_pose;
  const DynamicsTerms terms = EvaluateDynamics(DefaultConfig().platform, q, Vector6d::Zero());
  BarrierEvaluation e;
  EvaluateBarriers(c, q, Vector6d::Zero(), terms, terms.H.partialPivLu().solve(terms.G), &e);
  EXPECT_EQ(e.g_p, Vector6d::Zero());
  EXPECT_DOUBLE_EQ(e.psi_p, e.h_pos);  // at rest every dh_D is zero
}

}  // namespace
}  // namespace stewart::safety::test
