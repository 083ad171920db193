// psi_p, psi_v and g_p, g_v checked against an independent computation:
// Psi_c(F) = d/dt h_c + h_c, with d/dt h_c a central time difference of the
// composed barrier along the trajectory that the real model's forward
// dynamics gives for F (so it also checks the power-balance identity the
// energy barrier relies on), and g = dPsi/dF by finite differences.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

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
  return {(plus.h_pos - minus.h_pos) / (2 * dt) + c.position_rate_per_s * now.h_pos,
          (plus.h_vel - minus.h_vel) / (2 * dt) + c.velocity_rate_per_s * now.h_vel};
}

TEST(BarrierGradient, PsiAndGMatchTheModelsForwardDynamics) {
  for (const double rate : {1.0, 20.0}) {
    SCOPED_TRACE("class-K rate " + std::to_string(rate));
    SafetyConfig config = RichSafetyConfig();
    config.velocity_rate_per_s = rate;
    config.position_rate_per_s = 0.5 * rate;
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

namespace stewart::safety::test {
namespace {

TEST(RobustMarginAndFriction, ShiftPsiExactlyAndTheFilterKeepsTheMargin) {
  SafetyConfig plain = RichSafetyConfig();
  plain.leg_friction_nspm = 0.0;
  SafetyConfig robust = plain;
  robust.velocity_robust_margin_mps2 = 0.004;
  robust.position_robust_margin_w = 0.03;
  SafetyConfig friction = plain;
  friction.leg_friction_nspm = 3.0;
  SafetyFilter f_plain(DefaultConfig().platform, plain, DefaultConfig().actuators);
  SafetyFilter f_robust(DefaultConfig().platform, robust, DefaultConfig().actuators);
  SafetyFilter f_friction(DefaultConfig().platform, friction, DefaultConfig().actuators);
  std::mt19937 rng(5);
  int robust_active_only = 0;
  for (int n = 0; n < 2000; ++n) {
    const Vector6d q = RandomPoseInLimits(&rng);
    const Vector6d qd = RandomVelocity(&rng);
    const DynamicsTerms terms = EvaluateDynamics(DefaultConfig().platform, q, qd);
    const Vector6d f_des = RandomNominalForce(terms, &rng);
    SafetyDiagnostics dp, dr, df, dshift;
    f_plain.StepWithTerms(terms, q, qd, f_des, &dp);
    const Vector6d f_r = f_robust.StepWithTerms(terms, q, qd, f_des, &dr);
    EXPECT_NEAR(dr.barriers.psi_v, dp.barriers.psi_v - 0.004, 1e-12);
    EXPECT_NEAR(dr.barriers.psi_p, dp.barriers.psi_p - 0.03, 1e-12);
    if (!dr.infeasible) {
      // At F* the conditions hold with the margin.
      EXPECT_GE(dp.barriers.psi_v + dp.barriers.g_v.dot(f_r - f_des), 0.004 - 1e-9);
      EXPECT_GE(dp.barriers.psi_p + dp.barriers.g_p.dot(f_r - f_des), 0.03 - 1e-9);
    }
    if (dp.filter_case == FilterCase::kNone && dr.filter_case != FilterCase::kNone) {
      ++robust_active_only;
    }
    // Friction: the conditions are those of the frictionless model at the
    // force the legs really push, F - b H^T qd.
    const Vector6d friction_n = LegViscousFriction(3.0, terms.H.transpose() * qd);
    const Vector6d f_f = f_friction.StepWithTerms(terms, q, qd, f_des, &df);
    const Vector6d f_shift = f_plain.StepWithTerms(terms, q, qd, f_des + friction_n, &dshift);
    EXPECT_NEAR(df.barriers.psi_v, dshift.barriers.psi_v,
                1e-9 * (1 + std::fabs(df.barriers.psi_v)));
    EXPECT_NEAR(df.barriers.psi_p, dshift.barriers.psi_p,
                1e-9 * (1 + std::fabs(df.barriers.psi_p)));
    EXPECT_LE((f_f + friction_n - f_shift).norm(), 1e-9 * (1 + f_shift.norm())) << "sample " << n;
  }
  EXPECT_GT(robust_active_only, 10);  // the margin made the filter act where it did not
}

}  // namespace
}  // namespace stewart::safety::test
