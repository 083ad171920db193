// Dry friction the model does not have (the bounds: up to 0.3 N per leg):
// a leg's friction is -F_c sign(leg speed), so the model error d holds
// -H diag(F_c) sign(ld), and when a command step reverses legs that were
// creeping, d changes by up to 2 F_c per leg within a few samples. The
// platform creeps (y at -1 mm/s, so some legs lengthen and some shorten)
// until d has learnt the friction, then the command steps: x and y
// accelerate at 0.2 m/s^2 and it rolls at 2 rad/s^2, reversing legs, as when
// the filter switches case. Without the force-change allowance the gyro and
// the accelerometer disagree with the model beyond their gates until d's
// slow walk catches up, and the rates and the velocity follow the model
// instead of the platform until the legs are gated too and the estimate
// restarts (a random campaign run, 0.29 N of dry friction on its legs,
// exceeded xd by 2.9 mm/s that way; it held without the friction); with it,
// the command's change widens d's uncertainty by a share of H dF and d
// follows the flip.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "ekf_harness.h"
#include "stewart/config/default_config.h"
#include "stewart/estimator/ekf.h"
#include "stewart/model/dynamics.h"
#include "stewart/model/imu.h"
#include "stewart/model/kinematics.h"

namespace stewart {
namespace {

struct ReversalRun {
  int divergences = 0;
  int accel_gated = 0;
  int gyro_gated = 0;
  double worst_xd_error_mps = 0.0;      ///< after the step
  double worst_rate_error_radps = 0.0;  ///< roll rate, after the step
};

ReversalRun RunReversal(double force_change_std) {
  StackConfig c = DefaultStackConfig();
  c.estimator.disturbance_force_change_std = force_change_std;
  c.estimator.disturbance_friction_flip_std_n = 0.0;  // this allowance alone
  Ekf ekf(c.platform, c.actuators, c.sensors, c.estimator, c.home_pose);
  constexpr double kDryFrictionN = 0.3;
  constexpr double kDt = 1e-3;
  constexpr int kArm = 200, kStep = 1200, kEnd = 1400;
  Vector6d qdd_step = Vector6d::Zero();
  qdd_step(0) = 0.2;
  qdd_step(1) = 0.2;
  qdd_step(3) = 2.0;
  Vector6d q = c.home_pose, qd = Vector6d::Zero();
  ReversalRun run;
  for (int k = 0; k < kEnd; ++k) {
    if (k == kArm) qd(1) = -1e-3;  // the drive on: the platform creeps
    const Vector6d qdd = k >= kStep ? qdd_step : Vector6d::Zero();
    const SensorSample s = test::NoiselessSample(c, k, k < kArm, q, qd, qdd);
    const UpdateResult r = ekf.Update(s);
    if (r.Has(kEventDiverged)) ++run.divergences;
    if (k >= kStep) {
      if (r.Has(kGateAccel)) ++run.accel_gated;
      if (r.Has(kGateGyro)) ++run.gyro_gated;
      if (r.has_estimate) {
        const Estimate& e = ekf.estimate();
        run.worst_xd_error_mps = std::max(run.worst_xd_error_mps, std::abs(e.qd(0) - qd(0)));
        run.worst_rate_error_radps =
            std::max(run.worst_rate_error_radps, std::abs(e.qd(3) - qd(3)));
      }
    }
    // The command that makes the truth's motion: the model's force (with
    // its viscous friction), plus what the legs' dry friction takes.
    const DynamicsTerms terms = EvaluateDynamics(c.platform, q, qd);
    const Vector6d leg_speed_mps = terms.H.transpose() * qd;
    // The sign smoothed over 1 mm/s, as plant_sim's dry friction.
    const Vector6d dry_n =
        kDryFrictionN * leg_speed_mps.unaryExpr([](double v) { return std::tanh(v / 1e-3); });
    const Vector6d command_n =
        InverseDynamics(terms, qdd) -
        LegViscousFriction(c.actuators.viscous_friction_nspm, leg_speed_mps) + dry_n;
    ekf.SetForceCommand(s.utime, k < kArm ? Vector6d::Zero() : command_n, k < kArm);
    if (k >= kArm) {
      q += qd * kDt + 0.5 * qdd * kDt * kDt;
      qd += qdd * kDt;
    }
  }
  std::printf(
      "[force change] allowance std %.2f: after the step %d accelerometer and %d gyro samples "
      "gated of %d; worst xd error %.2f mm/s, roll rate %.1f mrad/s\n",
      force_change_std, run.accel_gated, run.gyro_gated, kEnd - kStep, 1e3 * run.worst_xd_error_mps,
      1e3 * run.worst_rate_error_radps);
  return run;
}

TEST(EkfForceChange, LegsReversedByACommandStepThroughDryFrictionAreFollowedWithoutARestart) {
  const ReversalRun before = RunReversal(0.0);
  const ReversalRun after = RunReversal(0.1);
  // Without the allowance the gyro is gated while the rates drift on the
  // model; the velocity follows, the legs are gated and the estimate
  // restarts ...
  EXPECT_GE(before.gyro_gated, 10);
  EXPECT_GT(before.divergences, 0);
  // ... with it d follows the flip: no restart, and the rates and the
  // velocity stay within a fraction of those errors.
  EXPECT_EQ(after.divergences, 0);
  EXPECT_LT(after.worst_rate_error_radps, 0.5 * before.worst_rate_error_radps);
  EXPECT_LT(after.worst_xd_error_mps, 0.5 * before.worst_xd_error_mps);
}

/// The trace of d's force rows' covariance (N^2) after the sample that
/// follows a step of leg 0's command by `step_n`, on a still platform held
/// at home by the model's force.
double ForceRowsVarianceAfterAStep(double step_n, double cap_n) {
  StackConfig c = DefaultStackConfig();
  c.estimator.disturbance_force_change_cap_n = cap_n;
  Ekf ekf(c.platform, c.actuators, c.sensors, c.estimator, c.home_pose);
  const Vector6d q = c.home_pose, qd = Vector6d::Zero();
  const Vector6d hold_n = InverseDynamics(EvaluateDynamics(c.platform, q, qd), Vector6d::Zero());
  constexpr int kArm = 200, kStep = 600;
  for (int k = 0; k <= kStep + 1; ++k) {
    const SensorSample s = test::NoiselessSample(c, k, k < kArm, q, qd, Vector6d::Zero());
    ekf.Update(s);
    Vector6d command_n = k < kArm ? Vector6d::Zero() : hold_n;
    if (k == kStep) command_n(0) += step_n;
    ekf.SetForceCommand(s.utime, command_n, k < kArm);
  }
  return ekf.P().block<3, 3>(kEkfDisturbance, kEkfDisturbance).trace();
}

// Each leg's change counts at most estimator.disturbance.force_change_cap_n:
// a larger one widens d as much as the cap, a smaller one in proportion.
TEST(EkfForceChange, EachLegsChangeCountsAtMostTheCap) {
  constexpr double kCapN = 2.0;
  constexpr double kNoCap = std::numeric_limits<double>::infinity();
  const double steady = ForceRowsVarianceAfterAStep(0.0, kCapN);
  const double small_capped = ForceRowsVarianceAfterAStep(1.0, kCapN);
  const double small_uncapped = ForceRowsVarianceAfterAStep(1.0, kNoCap);
  const double at_cap = ForceRowsVarianceAfterAStep(kCapN, kCapN);
  const double large_capped = ForceRowsVarianceAfterAStep(10.0, kCapN);
  const double large_uncapped = ForceRowsVarianceAfterAStep(10.0, kNoCap);
  std::printf(
      "[force change] d's force-row variance after a step (N^2): none %.3g, 1 N %.3g, 2 N %.3g, "
      "10 N %.3g capped at 2 N, %.3g uncapped\n",
      steady, small_capped, at_cap, large_capped, large_uncapped);
  EXPECT_GT(small_capped, steady);
  EXPECT_NEAR(small_capped, small_uncapped, 1e-9 * small_uncapped);
  // The 10 N step's prediction differs from the 2 N step's, so the sample's
  // corrections take a little more or less of the variance; within a tenth
  // of what the step added.
  EXPECT_NEAR(large_capped, at_cap, 0.1 * (at_cap - steady));
  // Uncapped, the allowance grows with the square of the step: 25 times the
  // cap's at 10 N.
  EXPECT_GT(large_uncapped - steady, 10.0 * (at_cap - steady));
}

}  // namespace
}  // namespace stewart
