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
#include <limits>
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
  std::vector<double> d_force_n;  ///< |d's force rows| after each sample
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
                 const std::function<Vector6d(int, const DynamicsTerms&)>& push,
                 const std::function<void(int, SensorSample*)>& edit_sample = {}) {
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
    SensorSample sample = test::NoiselessSample(c, k, false, q, qd, qdd);
    if (edit_sample) edit_sample(k, &sample);
    const UpdateResult r = ekf.Update(sample);
    run.d_force_n.push_back(ekf.estimate().disturbance_n.head<3>().norm());
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

// The early jump as shipped and measured in the campaigns (docs/campaign.md):
// 50 calm samples (Config.EarlyJump pins the shipped value) and the
// config's step limit.
const StackConfig& EarlyJumpConfig() {
  static const StackConfig c = WithEarlyJump(50);
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
  constexpr int kPush = 400, kEnd = 430;
  const auto push = [](int k, const DynamicsTerms&) { return PushX(k, kPush); };
  const JumpRun early = RunHover(EarlyJumpConfig(), kEnd, kEnd, 0.0, 0, push);
  const JumpRun off = RunHover(WithEarlyJump(0), kEnd, kEnd, 0.0, 0, push);
  std::printf("[early jump] a 3 N push at sample %d: jump at %d (early jump off: %d)\n", kPush,
              early.FirstJumpFrom(0), off.FirstJumpFrom(0));
  EXPECT_EQ(early.FirstJumpFrom(0), kPush);
  EXPECT_EQ(off.FirstJumpFrom(0),
            kPush + DefaultStackConfig().estimator.disturbance_jump_after_samples - 1);
  EXPECT_EQ(early.divergences, 0);
  EXPECT_EQ(off.divergences, 0);
}

TEST(EkfEarlyJump, AStepSoonAfterAnotherDisagreementWaitsForItsSecondSample) {
  // The push grows from 3 N to 6 N 20 samples after it began: the
  // accelerometer disagreed too lately for the calm condition.
  const int calm = EarlyJumpConfig().estimator.disturbance_early_jump_calm_samples;
  constexpr int kPush = 400, kGrow = 420, kEnd = 440;
  ASSERT_LT(kGrow - kPush, calm);
  const auto push = [](int k, const DynamicsTerms&) {
    return Vector6d(PushX(k, kPush) + PushX(k, kGrow));
  };
  const JumpRun run = RunHover(EarlyJumpConfig(), kEnd, kEnd, 0.0, 0, push);
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
  // A command step (0.1 N per leg) the actuators apply two samples late, and
  // from its first sample a push along what the step adds (-8 H dF, ~4.4 N,
  // within the early jump's step limit): the innovation lies along the
  // direction the latency allowance answers, but 9 times its size, so it
  // gates; a late command of another size could explain it, and the EKF
  // waits. The same push without the step (no latency direction) jumps at
  // once.
  ASSERT_GT(DefaultStackConfig().estimator.command_latency_allowance_s, 0.0);
  static constexpr int kStep = 400, kEnd = 430;
  static constexpr double kStepN = 0.1;
  const auto push = [](int k, const DynamicsTerms& terms) {
    return k > kStep ? Vector6d(-8.0 * terms.H * Vector6d::Constant(kStepN))
                     : Vector6d(Vector6d::Zero());
  };
  const JumpRun late_step = RunHover(EarlyJumpConfig(), kEnd, kStep, kStepN, 2, push);
  const JumpRun steady = RunHover(EarlyJumpConfig(), kEnd, kEnd, 0.0, 0, push);
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

TEST(EkfEarlyJump, OneSampleBeyondAnyPushWaitsForTheNext) {
  // One accelerometer sample reads free fall (no specific force: a glitch,
  // or a plant started with its legs not yet held) on a calm platform at
  // rest. The next samples agree again: nothing happened.
  constexpr int kGlitch = 400, kEnd = 430;
  const auto no_push = [](int, const DynamicsTerms&) { return Vector6d(Vector6d::Zero()); };
  const auto free_fall = [](int k, SensorSample* s) {
    if (k == kGlitch) s->accel_mps2.setZero();
  };
  const StackConfig& limited_config = EarlyJumpConfig();
  ASSERT_LT(limited_config.estimator.disturbance_early_jump_max_step_n, 9.0);
  const JumpRun limited = RunHover(limited_config, kEnd, kEnd, 0.0, 0, no_push, free_fall);
  StackConfig unlimited_config = EarlyJumpConfig();
  unlimited_config.estimator.disturbance_early_jump_max_step_n =
      std::numeric_limits<double>::infinity();
  const JumpRun unlimited = RunHover(unlimited_config, kEnd, kEnd, 0.0, 0, no_push, free_fall);
  std::printf(
      "[early jump] one free-fall sample at rest: |d| %.2f N after it, %.2f N at the end (%zu "
      "jumps); without the step limit %.2f N after it (%zu jumps, the first at %d), %.2f N at "
      "the end\n",
      limited.d_force_n[kGlitch], limited.d_force_n.back(), limited.jumps.size(),
      unlimited.d_force_n[kGlitch], unlimited.jumps.size(), unlimited.FirstJumpFrom(0),
      unlimited.d_force_n.back());
  // The limit undoes the jump: the sample is only gated and d stays put.
  EXPECT_TRUE(limited.jumps.empty());
  EXPECT_LT(limited.d_force_n[kGlitch], 0.1);
  EXPECT_LT(limited.d_force_n.back(), 0.1);
  // Without it the sample is taken as a step of ~9 N, which the next
  // samples take back only through another jump.
  EXPECT_EQ(unlimited.FirstJumpFrom(0), kGlitch);
  EXPECT_GT(unlimited.d_force_n[kGlitch],
            limited_config.estimator.disturbance_early_jump_max_step_n);
}

}  // namespace
}  // namespace stewart
