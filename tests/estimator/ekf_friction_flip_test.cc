// The friction-flip allowance in the EKF alone: a leg's dry friction
// -F_c sign(ld) flips when the leg reverses, so d's covariance opens along
// that leg's column of H when the estimate's speed of the leg, last beyond
// estimator.disturbance.friction_flip_speed_mps one way, is beyond it the
// other way; not while the legs keep their direction, nor while their
// speeds stay within the band. The platform (the model exactly, no
// friction: the allowance acts on the estimate's speeds, not on the truth)
// moves along y at a steady speed, then reverses within 10 ms; its
// accelerometer is taken as noisy, so that what the allowance opens stays
// open long enough to be read after the samples that follow.
// What the allowance does for a platform whose legs do have dry friction is
// shown in the closed loop (FrictionFlip.*, tests/closed_loop).
#include <gtest/gtest.h>

#include <cstdio>

#include "ekf_harness.h"
#include "stewart/config/default_config.h"
#include "stewart/estimator/ekf.h"
#include "stewart/model/dynamics.h"
#include "stewart/model/imu.h"
#include "stewart/model/kinematics.h"

namespace stewart {
namespace {

/// The trace of d's force rows' covariance (N^2) 20 ms after the platform
/// began to reverse from +speed to -speed along y (or at the same time
/// without the reversal), and the largest estimated leg speed (m/s).
struct FlipRun {
  double force_rows_variance_n2 = 0.0;
  double max_leg_speed_mps = 0.0;
};

FlipRun RunReversal(double flip_std_n, double band_mps, double speed_mps, bool reverse) {
  StackConfig c = DefaultStackConfig();
  c.estimator.disturbance_friction_flip_std_n = flip_std_n;
  c.estimator.disturbance_friction_flip_speed_mps = band_mps;
  // An accelerometer far noisier than the shipped one: the shipped one pins
  // d within a sample, and what the allowance opened would be gone before
  // it could be read here.
  c.sensors.accel_noise_std_mps2 = 2.0;
  Ekf ekf(c.platform, c.actuators, c.sensors, c.estimator, c.home_pose);
  constexpr double kDt = 1e-3;
  constexpr int kArm = 200, kReverse = 700, kTurnSamples = 10, kEnd = kReverse + 20;
  Vector6d q = c.home_pose, qd = Vector6d::Zero();
  FlipRun run;
  for (int k = 0; k <= kEnd; ++k) {
    if (k == kArm) qd(1) = speed_mps;  // the drive on: the platform moves along y
    Vector6d qdd = Vector6d::Zero();
    if (reverse && k >= kReverse && k < kReverse + kTurnSamples) {
      qdd(1) = -2.0 * speed_mps / (kTurnSamples * kDt);
    }
    const SensorSample s = test::NoiselessSample(c, k, k < kArm, q, qd, qdd);
    ekf.Update(s);
    // The model's own force for the motion: the truth is the model.
    const DynamicsTerms terms = EvaluateDynamics(c.platform, q, qd);
    const Vector6d leg_speed_mps = terms.H.transpose() * qd;
    const Vector6d command_n = InverseDynamics(terms, qdd) -
                               LegViscousFriction(c.actuators.viscous_friction_nspm, leg_speed_mps);
    ekf.SetForceCommand(s.utime, k < kArm ? Vector6d::Zero() : command_n, k < kArm);
    if (k >= kArm) {
      run.max_leg_speed_mps = std::max(
          run.max_leg_speed_mps, (terms.H.transpose() * ekf.estimate().qd).cwiseAbs().maxCoeff());
      q += qd * kDt + 0.5 * qdd * kDt * kDt;
      qd += qdd * kDt;
    }
  }
  run.force_rows_variance_n2 = ekf.P().block<3, 3>(kEkfDisturbance, kEkfDisturbance).trace();
  return run;
}

TEST(EkfFrictionFlip, DsCovarianceOpensWhereTheEstimatesLegsReverseBeyondTheBand) {
  constexpr double kSpeedMps = 4e-3, kBandMps = 1e-3, kStdN = 0.1;
  const FlipRun off = RunReversal(0.0, kBandMps, kSpeedMps, true);
  const FlipRun on = RunReversal(kStdN, kBandMps, kSpeedMps, true);
  const FlipRun steady = RunReversal(kStdN, kBandMps, kSpeedMps, false);
  const FlipRun steady_off = RunReversal(0.0, kBandMps, kSpeedMps, false);
  const FlipRun within_band = RunReversal(kStdN, 10.0 * kSpeedMps, kSpeedMps, true);
  std::printf(
      "[friction flip] d's force-row variance 20 ms after a reversal at %.0f mm/s (legs up to "
      "%.1f mm/s): off %.4g N^2, on %.4g; band 10x the speed %.4g; no reversal %.4g (off %.4g)\n",
      1e3 * kSpeedMps, 1e3 * on.max_leg_speed_mps, off.force_rows_variance_n2,
      on.force_rows_variance_n2, within_band.force_rows_variance_n2, steady.force_rows_variance_n2,
      steady_off.force_rows_variance_n2);
  ASSERT_GT(on.max_leg_speed_mps, 2.0 * kBandMps);  // some legs do leave the band
  // Reversed legs beyond the band: d opens by std^2 along each reversed
  // leg (a unit force direction each); the samples after the flip take most
  // of it back, a tenth of one leg's stays after 20 ms.
  EXPECT_GT(on.force_rows_variance_n2 - off.force_rows_variance_n2, 0.1 * kStdN * kStdN);
  // No reversal, or none beyond the band: nothing added.
  EXPECT_DOUBLE_EQ(steady.force_rows_variance_n2, steady_off.force_rows_variance_n2);
  EXPECT_DOUBLE_EQ(within_band.force_rows_variance_n2, off.force_rows_variance_n2);
}

}  // namespace
}  // namespace stewart
