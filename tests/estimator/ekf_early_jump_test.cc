// A push on a platform at rest: the accelerometer sees it on its first
// sample, but the EKF re-opened d only on the jump_after_samples-th gated
// one, a sample the push moved the platform unmodelled (and the filter
// answered the estimate's velocity, not the platform's). With
// early_jump_calm_samples the first gated sample already jumps when the
// accelerometer agreed for that many samples before and the innovation stays
// beyond the gate whatever share of it a late command could explain.
// The campaign's push runs are what measured it (docs/campaign.md).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <functional>
#include <vector>

#include "ekf_harness.h"
#include "stewart/config/default_config.h"
#include "stewart/estimator/ekf.h"
#include "stewart/model/dc_motor.h"
#include "stewart/model/dynamics.h"

namespace stewart {
namespace {

constexpr double kDt = 1e-3;

struct JumpRun {
  std::vector<int> jumps;        ///< samples flagged kEventDisturbanceJump
  std::vector<int> accel_gated;  ///< samples flagged kGateAccel
  int divergences = 0;
  int FirstJumpFrom(int k) const {
    for (const int j : jumps) {
      if (j >= k) return j;
    }
    return -1;
  }
};

// The model's platform driven with its hover force, noiseless samples, its
// legs' viscous friction; from sample `step_k` the command is the hover
// force plus `step_n` per leg, applied `latency_samples` late by the truth;
// `push(k, q)` is the external generalised force (N, N m) on the truth at
// sample k.
JumpRun RunHover(const StackConfig& c, int end_k, int step_k, double step_n, int latency_samples,
            const std::function<Vector6d(int, const DynamicsTerms&)>& push) {
  Ekf ekf = test::MakeEkf(c);
  const Vector6d hover_n = InverseDynamics(
      EvaluateDynamics(c.platform, c.home_pose, Vector6d::Zero()), Vector6d::Zero());
  const Vector6d stepped_n = hover_n + Vector6d::Constant(step_n);
  const double damping_nspm = ModelLegDampingNspm(c.actuators);
  Vector6d q = c.home_pose, qd = Vector6d::Zero();
  JumpRun run;
  for (int k = 0; k < end_k; ++k) {
    const DynamicsTerms terms = EvaluateDynamics(c.platform, q, qd);
    const Vector6d applied_n = k > step_k + latency_samples ? stepped_n : hover_n;
    const Vector6d friction_n = LegViscousFriction(damping_nspm, terms.H.transpose() * qd);
    const Vector6d qdd = ForwardDynamics(terms, applied_n + friction_n, push(k, terms));
    const UpdateResult r = ekf.Update(test::NoiselessSample(c, k, false, q, qd, qdd));
    if (r.Has(kEventDisturbanceJump)) run.jumps.push_back(k);
    if (r.Has(kGateAccel)) run.accel_gated.push_back(k);
    if (r.Has(kEventDiverged)) ++run.divergences;
    ekf.SetForceCommand(1'000'000 + 1000 * static_cast<int64_t>(k),
                        k < step_k ? hover_n : stepped_n);
    q += qd * kDt + 0.5 * qdd * kDt * kDt;
    qd += qdd * kDt;
  }
  return run;
}

StackConfig WithEarlyJump(int calm_samples) {
  StackConfig c = DefaultStackConfig();
  c.estimator.disturbance_early_jump_calm_samples = calm_samples;
  return c;
}

// 3 N along x from sample `from_k` on (through {P}'s origin: a force alone).
Vector6d PushX(int k, int from_k) {
  Vector6d q_push = Vector6d::Zero();
  if (k >= from_k) q_push(0) = 3.0;
  return q_push;
}

TEST(EkfEarlyJump, APushOnACalmPlatformJumpsOnItsFirstGatedSample) {
  ASSERT_GE(DefaultStackConfig().estimator.disturbance_jump_after_samples, 2);
  ASSERT_GT(DefaultStackConfig().estimator.disturbance_early_jump_calm_samples, 0);
  constexpr int kPush = 400, kEnd = 430;
  const auto push = [](int k, const DynamicsTerms&) { return PushX(k, kPush); };
  const JumpRun shipped = RunHover(DefaultStackConfig(), kEnd, kEnd, 0.0, 0, push);
  const JumpRun off = RunHover(WithEarlyJump(0), kEnd, kEnd, 0.0, 0, push);
  std::printf("[early jump] a 3 N push at sample %d: jump at %d (early jump off: %d)\n", kPush,
              shipped.FirstJumpFrom(0), off.FirstJumpFrom(0));
  EXPECT_EQ(shipped.FirstJumpFrom(0), kPush);
  EXPECT_EQ(off.FirstJumpFrom(0),
            kPush + DefaultStackConfig().estimator.disturbance_jump_after_samples - 1);
  EXPECT_EQ(shipped.divergences, 0);
  EXPECT_EQ(off.divergences, 0);
}

TEST(EkfEarlyJump, AStepSoonAfterAnotherDisagreementWaitsForItsSecondSample) {
  // The push grows from 3 N to 6 N 20 samples after it began: the
  // accelerometer disagreed too lately for the calm condition.
  const int calm = DefaultStackConfig().estimator.disturbance_early_jump_calm_samples;
  constexpr int kPush = 400, kGrow = 420, kEnd = 440;
  ASSERT_LT(kGrow - kPush, calm);
  const auto push = [](int k, const DynamicsTerms&) {
    return Vector6d(PushX(k, kPush) + PushX(k, kGrow));
  };
  const JumpRun run = RunHover(DefaultStackConfig(), kEnd, kEnd, 0.0, 0, push);
  std::printf("[early jump] the push grows at sample %d: jump at %d\n", kGrow,
              run.FirstJumpFrom(kGrow));
  EXPECT_EQ(run.FirstJumpFrom(kPush), kPush);
  EXPECT_EQ(run.FirstJumpFrom(kGrow),
            kGrow + DefaultStackConfig().estimator.disturbance_jump_after_samples - 1);
  // ... and only on it: the sample before was gated.
  EXPECT_NE(std::find(run.accel_gated.begin(), run.accel_gated.end(), kGrow),
            run.accel_gated.end());
}

TEST(EkfEarlyJump, AnInnovationALateCommandCouldExplainWaitsForItsSecondSample) {
  // A command step (0.3 N per leg) the actuators apply two samples late, and
  // from its first sample a push along what the step adds (-4 H dF): the
  // innovation lies along the direction the latency allowance answers, but
  // beyond its size, so it gates; a late command of another size could
  // explain it, and the EKF waits. The same push without the step (no
  // latency direction) jumps at once.
  ASSERT_GT(DefaultStackConfig().estimator.command_latency_allowance_s, 0.0);
  static constexpr int kStep = 400, kEnd = 430;
  static constexpr double kStepN = 0.3;
  const auto push = [](int k, const DynamicsTerms& terms) {
    return k > kStep ? Vector6d(-4.0 * terms.H * Vector6d::Constant(kStepN))
                     : Vector6d(Vector6d::Zero());
  };
  const JumpRun late_step = RunHover(DefaultStackConfig(), kEnd, kStep, kStepN, 2, push);
  const JumpRun steady = RunHover(DefaultStackConfig(), kEnd, kEnd, 0.0, 0, push);
  std::printf(
      "[early jump] a push along a late step's direction from sample %d: jump at %d; without the "
      "step: %d\n",
      kStep + 1, late_step.FirstJumpFrom(0), steady.FirstJumpFrom(0));
  ASSERT_FALSE(late_step.accel_gated.empty());
  EXPECT_EQ(late_step.accel_gated.front(), kStep + 1);
  EXPECT_EQ(late_step.FirstJumpFrom(0),
            kStep + DefaultStackConfig().estimator.disturbance_jump_after_samples);
  EXPECT_EQ(steady.FirstJumpFrom(0), kStep + 1);
}

}  // namespace
}  // namespace stewart
