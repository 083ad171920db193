// Closed-loop invariance in-process: the model, a feedback-linearising PD
// controller (paper eq. 3) with setpoints far beyond every limit, and the
// filter evaluated inside every RK4 stage (continuous-time feedback), from
// random initial states inside the composed safe set. No constrained
// quantity may exceed its limit by more than kTolerance (docs/safety.md).
#include <gtest/gtest.h>

#include <cmath>

#include "safety_test_support.h"
#include "stewart/model/kinematics.h"

namespace stewart::safety::test {
namespace {

// RK4 local error at the filter's case switches is O(dt^2 * jump in qdd)
// ~ 1e-12 * 10 m/s^2: 1e-6 is far above rounding and far below any margin.
constexpr double kTolerance = 1e-6;
// The composed (LSE) barrier makes the closed loop stiff: its curvature is
// k var(dh_i/dt), so the step must resolve 1/(k |dh_i/dt|) (docs/safety.md,
// "Sampled-data caveat"). With k_velocity = 2e3 that is ~1e-5 s; 1e-6 s
// keeps RK4 accurate, a few hundredths of a second of simulation per run.
constexpr double kDt = 1e-6;
constexpr double kDuration = 0.06;
// Runs per seed; the seeds below are separate ctest tests so they run in
// parallel: 10 x 4 = 40 random initial states in all.
constexpr int kRuns = 4;

struct Controller {
  Vector6d q_des;
  Vector6d kp, kd;
  Vector6d Force(const DynamicsTerms& t, const Vector6d& q, const Vector6d& qd) const {
    const Vector6d qdd = -kp.cwiseProduct(q - q_des) - kd.cwiseProduct(qd);
    return InverseDynamics(t, qdd);
  }
};

// Largest excess of any constrained quantity over its limit (<= 0 inside).
double WorstExcess(const SafetyConfig& s, const Vector6d& q, const Vector6d& qd) {
  double worst = -1e9;
  for (const PositionLimitConfig& l : s.position_limits) {
    if (l.upper) worst = std::max(worst, q(l.axis) - *l.upper);
    if (l.lower) worst = std::max(worst, *l.lower - q(l.axis));
  }
  for (const VelocityLimitConfig& l : s.velocity_limits) {
    if (l.upper) worst = std::max(worst, qd(l.axis) - *l.upper);
    if (l.lower) worst = std::max(worst, *l.lower - qd(l.axis));
  }
  const PlatformParams& p = DefaultConfig().platform;
  const Vector6d len = InverseKinematics(p, q);
  worst = std::max(worst, len.maxCoeff() - (p.leg_max_length_m - s.leg_stroke.margin_m));
  worst = std::max(worst, (p.leg_min_length_m + s.leg_stroke.margin_m) - len.minCoeff());
  return worst;
}

class ClosedLoop : public ::testing::TestWithParam<unsigned> {};

TEST_P(ClosedLoop, NothingLeavesTheSafeSet) {
  SafetyConfig config = RichSafetyConfig();
  config.k_velocity = 2e3;  // ln(8)/k = 1e-3 m/s: 7 % of the smallest margin
  SafetyFilter filter(DefaultConfig().platform, config, DefaultConfig().actuators);
  const PlatformParams& p = DefaultConfig().platform;
  std::mt19937 rng(GetParam());
  std::uniform_int_distribution<int> sign(0, 1);
  double worst = -1e9;
  int runs = 0, infeasible_steps = 0, active_steps = 0;
  while (runs < kRuns) {
    Vector6d q = RandomPoseInLimits(&rng);
    Vector6d qd = RandomVelocity(&rng) * 0.3;
    SafetyDiagnostics d;
    filter.Step(q, qd, Vector6d::Zero(), &d);
    if (!(d.barriers.h_pos > 0.0 && d.barriers.h_vel > 0.0)) continue;  // start inside
    ++runs;
    Controller ctrl;
    // Far beyond every limit, in a random direction per axis.
    ctrl.q_des << (sign(rng) ? 0.5 : -0.5), (sign(rng) ? 0.5 : -0.5), (sign(rng) ? 0.8 : 0.1),
        (sign(rng) ? 0.6 : -0.6), (sign(rng) ? 0.4 : -0.4), (sign(rng) ? 0.8 : -0.8);
    ctrl.kp = DefaultConfig().controller.kp;
    ctrl.kd = DefaultConfig().controller.kd;
    auto rhs = [&](const Vector6d& qs, const Vector6d& qds, Vector6d* qdd) {
      const DynamicsTerms t = EvaluateDynamics(p, qs, qds);
      SafetyDiagnostics di;
      const Vector6d f = filter.StepWithTerms(t, qs, qds, ctrl.Force(t, qs, qds), &di);
      if (di.infeasible) ++infeasible_steps;
      if (di.flags & kFlagFilterActive) ++active_steps;
      *qdd = ForwardDynamics(t, f);
    };
    for (double t = 0.0; t < kDuration; t += kDt) {
      Vector6d a1, a2, a3, a4;
      rhs(q, qd, &a1);
      rhs(q + 0.5 * kDt * qd, qd + 0.5 * kDt * a1, &a2);
      rhs(q + 0.5 * kDt * (qd + 0.5 * kDt * a1), qd + 0.5 * kDt * a2, &a3);
      rhs(q + kDt * (qd + 0.5 * kDt * a2), qd + kDt * a3, &a4);
      q += kDt * qd + kDt * kDt / 6.0 * (a1 + a2 + a3);
      qd += kDt / 6.0 * (a1 + 2 * a2 + 2 * a3 + a4);
      ASSERT_TRUE(q.allFinite() && qd.allFinite());
      const double excess = WorstExcess(config, q, qd);
      worst = std::max(worst, excess);
      ASSERT_LE(excess, kTolerance)
          << "run " << runs << " t " << t << "\nq " << q.transpose() << "\nqd " << qd.transpose();
    }
  }
  std::printf(
      "closed loop, seed %u: worst excess %.3g (tol %.1g), active stage evaluations %d, "
      "infeasible %d\n",
      GetParam(), worst, kTolerance, active_steps, infeasible_steps);
  EXPECT_GT(active_steps, 10000);  // the limits were really challenged
  EXPECT_GT(worst, -0.01);         // and approached
}

INSTANTIATE_TEST_SUITE_P(Seeds, ClosedLoop,
                         ::testing::Values(99u, 1u, 2u, 3u, 4u, 5u, 6u, 7u, 8u, 9u));

}  // namespace
}  // namespace stewart::safety::test
