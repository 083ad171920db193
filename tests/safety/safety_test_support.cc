#include "safety_test_support.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "stewart/config/default_config.h"
#include "stewart/model/kinematics.h"

namespace stewart::safety::test {

const StackConfig& DefaultConfig() { return DefaultStackConfig(); }

SafetyConfig RichSafetyConfig() {
  SafetyConfig s = DefaultConfig().safety;
  s.variant = SafetyVariant::kClosedForm;
  // The solver's tests use the sharp LSE and no robustness margin, so that
  // random states exercise every case; the tuned values are tested in the
  // closed loop (tests/closed_loop).
  s.k_velocity = 2e4;
  s.velocity_robust_margin_mps2 = 0.0;
  s.position_robust_margin_w = 0.0;
  // The paper's unit class-K rates: the velocity conditions bind on more of
  // the random states (BarrierGradient also checks other rates).
  s.velocity_rate_per_s = 1.0;
  s.position_rate_per_s = 1.0;
  // The solver sees the random nominals (up to 10 m/s^2) as they are: the
  // per-period bound would scale most of them to 1 m/s^2 and hide cases.
  // It has its own tests (nominal_bound_test.cc).
  s.sample_period_s = 0.0;
  // The solver's tests prove the composed closed form against its own QP;
  // the per-barrier step that may replace its answer is tested on its own
  // (per_barrier_test.cc).
  s.check_each_barrier = false;
  // The random states are drawn against these limits as written; the joint
  // tolerance's margin (a constant shift of each limit) has its own tests
  // (constraint_set_test.cc).
  s.joint_radius_tolerance_m = 0.0;
  s.joint_angle_tolerance_rad = 0.0;
  s.position_limits = {
      {0, -0.08, 0.11, 1.0, 1.0},
      {1, -0.10, 0.11, 1.5, 0.8},
      {2, 0.36, 0.51, 1.0, 1.2},
      {3, -0.15, 0.15, 0.5, 2.0},
  };
  s.velocity_limits = {
      {0, -0.015, 0.015, 1.0},
      {1, -0.015, 0.015, 1.0},
      {2, -0.010, 0.010, 2.0},
      {5, -0.10, 0.10, 1.5},
  };
  s.leg_stroke.enabled = true;
  s.leg_stroke.margin_m = 0.005;
  s.leg_stroke.alpha_e = 2.0;
  s.leg_stroke.alpha = 1.0;
  s.force_limits_enabled = false;
  return s;
}

Vector6d RandomPoseInLimits(std::mt19937* rng) {
  std::uniform_real_distribution<double> x(-0.08, 0.11), y(-0.10, 0.11), z(0.36, 0.51);
  std::uniform_real_distribution<double> phi(-0.15, 0.15), angle(-0.2, 0.2);
  const PlatformParams& p = DefaultConfig().platform;
  const double margin = RichSafetyConfig().leg_stroke.margin_m;
  for (;;) {
    Vector6d q;
    q << x(*rng), y(*rng), z(*rng), phi(*rng), angle(*rng), angle(*rng);
    const Vector6d l = InverseKinematics(p, q);
    if (PoseInWorkspace(p, q) && l.minCoeff() > p.leg_min_length_m + margin &&
        l.maxCoeff() < p.leg_max_length_m - margin) {
      return q;
    }
  }
}

namespace {
double LogUniform(std::mt19937* rng, double lo, double hi) {
  std::uniform_real_distribution<double> u(std::log(lo), std::log(hi));
  return std::exp(u(*rng));
}
Vector6d RandomDirection(std::mt19937* rng) {
  std::normal_distribution<double> n;
  Vector6d v;
  for (int i = 0; i < 6; ++i) v(i) = n(*rng);
  return v.normalized();
}
}  // namespace

Vector6d RandomVelocity(std::mt19937* rng) {
  Vector6d qd = RandomDirection(rng) * LogUniform(rng, 1e-4, 3e-2);
  qd.tail<3>() *= 3.0;  // rad/s: rotations are a bit faster
  return qd;
}

Vector6d RandomNominalForce(const DynamicsTerms& terms, std::mt19937* rng) {
  const Vector6d qdd = RandomDirection(rng) * LogUniform(rng, 1e-3, 10.0);
  return InverseDynamics(terms, qdd);
}

SupervisorConfig ArmedAtOnce() {
  SupervisorConfig c;
  c.auto_arm = true;
  c.arming_ramp_s = 0.0;
  c.fallback_latch_s = 0.0;
  return c;
}

double RelativeError(const Vector6d& a, const Vector6d& b) {
  return (a - b).norm() / std::max(b.norm(), 1.0);
}

void ExpectForceLimitsKkt(const Vector6d& f, const Vector6d& mu_force, bool force_limits,
                          double f_max_n, int sample) {
  if (!force_limits) {
    EXPECT_EQ(mu_force, Vector6d::Zero()) << "sample " << sample;
    return;
  }
  for (int i = 0; i < 6; ++i) {
    EXPECT_LE(std::fabs(f(i)), f_max_n * (1 + 1e-12)) << "sample " << sample;
    if (mu_force(i) > 0) {
      EXPECT_NEAR(f(i), f_max_n, 1e-9 * f_max_n) << "sample " << sample;
    }
    if (mu_force(i) < 0) {
      EXPECT_NEAR(f(i), -f_max_n, 1e-9 * f_max_n) << "sample " << sample;
    }
  }
}

FilterInput RandomFilterInput(std::mt19937* rng) {
  FilterInput x;
  x.q = RandomPoseInLimits(rng);
  x.qd = RandomVelocity(rng);
  x.terms = EvaluateDynamics(DefaultConfig().platform, x.q, x.qd);
  x.f_des = RandomNominalForce(x.terms, rng);
  return x;
}

FilterInput AtRestPushedAlongX(double accel_mps2) {
  FilterInput x;
  x.q = DefaultConfig().home_pose;
  x.qd = Vector6d::Zero();
  x.terms = EvaluateDynamics(DefaultConfig().platform, x.q, x.qd);
  x.f_des = InverseDynamics(x.terms, Vector6d::Unit(0) * accel_mps2);
  return x;
}

Vector6d HoverForce(const Vector6d& q) {
  const DynamicsTerms t = EvaluateDynamics(DefaultConfig().platform, q, Vector6d::Zero());
  return t.H.partialPivLu().solve(t.G);
}

SafetyFilter MakeRichFilter(bool force_limits, SafetyVariant variant) {
  SafetyConfig s = RichSafetyConfig();
  s.force_limits_enabled = force_limits;
  s.variant = variant;
  return SafetyFilter(DefaultConfig().platform, s, DefaultConfig().actuators);
}

}  // namespace stewart::safety::test
