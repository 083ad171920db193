// An accelerometer with a constant bias, as every MEMS part has before its
// calibration (the myRIO's class: tenths of a m/s^2). The platform is held,
// then lifted and lowered by the model's own forces (an exact model): the
// accelerometer reads the true specific force plus the bias. With the bias
// in the state (estimator.initial_accel_bias_std_mps2 > 0) the EKF learns it
// and keeps using the accelerometer; without, the bias is read as a model
// error d: the estimate of d is wrong by the bias times the platform's mass,
// and the accelerometer is gated whenever the motion makes the two disagree.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "stewart/config/default_config.h"
#include "stewart/estimator/ekf.h"
#include "stewart/model/dynamics.h"
#include "stewart/model/kinematics.h"

namespace stewart {
namespace {

struct BiasRun {
  int divergences = 0;
  int accel_gated = 0;
  Vector3d bias_estimate = Vector3d::Zero();
  double worst_d_n = 0.0;           ///< |d| (force rows), last second
  double worst_zd_error_mps = 0.0;  ///< last second
};

BiasRun RunWithBias(const Vector3d& bias_mps2, double initial_bias_std_mps2) {
  StackConfig c = DefaultStackConfig();
  c.estimator.initial_accel_bias_std_mps2 = initial_bias_std_mps2;
  c.estimator.accel_bias_walk_mps2_per_sqrt_s = 1e-4;
  c.estimator.estimate_accel_bias_z = true;  // a bias on every axis
  Ekf ekf(c.platform, c.actuators, c.sensors, c.estimator, c.home_pose);
  constexpr double kDt = 1e-3;
  constexpr int kArm = 200, kEnd = 3200;
  // z = z0 + A (1 - cos(w t)) once the drive is on: 10 mm up and down, 1 Hz.
  constexpr double kAmplitudeM = 0.005, kOmega = 2.0 * M_PI;
  BiasRun run;
  for (int k = 0; k < kEnd; ++k) {
    const double t = k < kArm ? 0.0 : (k - kArm) * kDt;
    Vector6d q = c.home_pose, qd = Vector6d::Zero(), qdd = Vector6d::Zero();
    q(2) += kAmplitudeM * (1.0 - std::cos(kOmega * t));
    qd(2) = kAmplitudeM * kOmega * std::sin(kOmega * t);
    qdd(2) = kAmplitudeM * kOmega * kOmega * std::cos(kOmega * t);
    if (k < kArm) qdd(2) = 0.0;
    SensorSample s;
    s.utime = 1'000'000 + 1000 * static_cast<int64_t>(k);
    s.drive_off = k < kArm;
    s.leg_length_m = InverseKinematics(c.platform, q);
    // Level platform: the specific force is (0, 0, g + zdd) in {P}.
    s.accel_mps2 = Vector3d(0.0, 0.0, c.platform.gravity_mps2 + qdd(2)) + bias_mps2;
    s.gyro_radps = c.sensors.gyro_bias_radps;
    const UpdateResult r = ekf.Update(s);
    if (r.Has(kEventDiverged)) ++run.divergences;
    if (r.Has(kGateAccel)) ++run.accel_gated;
    // The force that makes the next interval's motion the truth's.
    const Vector6d force_n = InverseDynamics(EvaluateDynamics(c.platform, q, qd), qdd);
    ekf.SetForceCommand(s.utime, k < kArm ? Vector6d::Zero() : force_n, k < kArm);
    if (k >= kEnd - 1000 && r.has_estimate) {
      const Estimate e = ekf.estimate();
      run.worst_d_n = std::max(run.worst_d_n, e.disturbance_n.head<3>().norm());
      run.worst_zd_error_mps = std::max(run.worst_zd_error_mps, std::abs(e.qd(2) - qd(2)));
    }
  }
  run.bias_estimate = ekf.estimate().accel_bias_mps2;
  std::printf(
      "[accel bias] bias (%.3f %.3f %.3f) m/s^2, initial std %.2f: %d restarts, %d accelerometer "
      "samples gated; estimate (%.3f %.3f %.3f); last second |d| <= %.3f N, |zd error| <= %.2f "
      "mm/s\n",
      bias_mps2.x(), bias_mps2.y(), bias_mps2.z(), initial_bias_std_mps2, run.divergences,
      run.accel_gated, run.bias_estimate.x(), run.bias_estimate.y(), run.bias_estimate.z(),
      run.worst_d_n, run.worst_zd_error_mps * 1e3);
  return run;
}

TEST(EkfAccelBias, AConstantBiasIsLearntNotTakenForAModelError) {
  // Without a bias the state changes nothing that matters. (The test's
  // forces leave a small d of their own, the legs' damping the motion
  // excites: the reference for the runs below.)
  const BiasRun unbiased = RunWithBias(Vector3d::Zero(), 0.1);
  EXPECT_EQ(unbiased.divergences, 0);
  EXPECT_LT(unbiased.bias_estimate.norm(), 0.01);
  EXPECT_LT(unbiased.worst_zd_error_mps, 0.5e-3);

  const Vector3d bias(0.15, -0.12, 0.10);
  const BiasRun learnt = RunWithBias(bias, 0.1);
  EXPECT_EQ(learnt.divergences, 0);
  EXPECT_LT((learnt.bias_estimate - bias).norm(), 0.02);
  EXPECT_NEAR(learnt.worst_d_n, unbiased.worst_d_n, 0.05);
  EXPECT_LT(learnt.worst_zd_error_mps, 0.5e-3);
  EXPECT_LT(learnt.accel_gated, 30);

  // Without the bias in the state (the shipped default: a calibrated
  // accelerometer) the same bias is read as d: d is off, and the velocity
  // estimate with it.
  const BiasRun taken_for_d = RunWithBias(bias, 0.0);
  EXPECT_EQ(taken_for_d.bias_estimate.norm(), 0.0);
  EXPECT_GT(taken_for_d.worst_d_n, unbiased.worst_d_n + 0.1);
  EXPECT_GT(taken_for_d.worst_zd_error_mps, 2e-3);
}

}  // namespace
}  // namespace stewart
