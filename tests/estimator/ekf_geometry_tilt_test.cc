// Joint centres that are not where the config says (within the bounds the
// stack is measured in: +-1 mm radius, +-0.5 deg angle per joint) tilt the
// pose the legs give by some mrad, while the accelerometer sees the true
// gravity direction. The EKF must not settle that disagreement with a wrong
// velocity (the safety filter keeps the velocity estimate, not the truth,
// below its limit): read in the platform frame it is a bias of the
// accelerometer, which the state b_a takes (docs/estimator.md, "The
// accelerometer's bias").
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include "stewart/config/default_config.h"
#include "stewart/estimator/ekf.h"
#include "stewart/model/dynamics.h"
#include "stewart/model/kinematics.h"

namespace stewart {
namespace {

Vector3d MovedJoint(const Vector3d& joint_m, double radius_offset_m, double angle_offset_rad) {
  const double r = joint_m.head<2>().norm();
  const double angle = std::atan2(joint_m(1), joint_m(0)) + angle_offset_rad;
  return Vector3d((r + radius_offset_m) * std::cos(angle), (r + radius_offset_m) * std::sin(angle),
                  joint_m(2));
}

// The first geometry within the bounds (seeded draws) whose legs tilt the
// home pose by more than 4 mrad in pitch: a geometry the campaign meets.
PlatformParams TiltingGeometry(const StackConfig& c, double* pitch_error_rad) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const double angle_rad = 0.5 * M_PI / 180.0;
  for (;;) {
    PlatformParams truth = c.platform;
    for (int i = 0; i < kNumLegs; ++i) {
      truth.base_joints_in_B_m.col(i) =
          MovedJoint(c.platform.base_joints_in_B_m.col(i), 1e-3 * unit(rng), angle_rad * unit(rng));
      truth.platform_joints_in_P_m.col(i) = MovedJoint(c.platform.platform_joints_in_P_m.col(i),
                                                       1e-3 * unit(rng), angle_rad * unit(rng));
    }
    const ForwardKinematicsResult fit =
        ForwardKinematics(c.platform, InverseKinematics(truth, c.home_pose), c.home_pose);
    *pitch_error_rad = fit.q(4) - c.home_pose(4);
    if (fit.converged && std::fabs(*pitch_error_rad) > 4e-3) return truth;
  }
}

// Sample k (1 kHz) of a level platform moving along x at (q, qd, qdd): the
// truth's legs, the accelerometer ({P} = {B}), a gyro that reads only its
// bias; then the command that makes that motion on the truth, the drive off
// before sample `arm`.
UpdateResult StepLevelAlongX(const StackConfig& c, const PlatformParams& truth, int k, int arm,
                             const Vector6d& q, const Vector6d& qd, const Vector6d& qdd, Ekf* ekf) {
  SensorSample s;
  s.utime = 1'000'000 + 1000 * static_cast<int64_t>(k);
  s.drive_off = k < arm;
  s.leg_length_m = InverseKinematics(truth, q);
  s.accel_mps2 = Vector3d(qdd(0), 0.0, c.platform.gravity_mps2);
  s.gyro_radps = c.sensors.gyro_bias_radps;
  const UpdateResult r = ekf->Update(s);
  const Vector6d force_n = InverseDynamics(EvaluateDynamics(truth, q, qd), qdd);
  ekf->SetForceCommand(s.utime, k < arm ? Vector6d::Zero() : force_n, k < arm);
  return r;
}

struct TiltRun {
  int divergences = 0;
  double worst_xd_error_mps = 0.0;  ///< while cruising
};

// Level platform: armed at rest, then accelerated smoothly along x to
// 12 mm/s and cruising (a velocity limit's neighbourhood), 4 s in all.
TiltRun RunCruise(const PlatformParams& truth, double initial_bias_std_mps2) {
  StackConfig c = DefaultStackConfig();
  c.estimator.initial_accel_bias_std_mps2 = initial_bias_std_mps2;
  Ekf ekf(c.platform, c.actuators, c.sensors, c.estimator, c.home_pose);
  constexpr double kDt = 1e-3, kSpeedMps = 0.012, kRampS = 1.0;
  constexpr int kArm = 500, kEnd = 4500, kCruiseFrom = 2500;
  TiltRun run;
  for (int k = 0; k < kEnd; ++k) {
    const double t = k < kArm ? 0.0 : (k - kArm) * kDt;
    Vector6d q = c.home_pose, qd = Vector6d::Zero(), qdd = Vector6d::Zero();
    // x(t): a raised-cosine acceleration ramp to kSpeedMps over kRampS.
    if (t < kRampS) {
      const double w = M_PI / kRampS;
      q(0) += 0.5 * kSpeedMps * (t - std::sin(w * t) / w);
      qd(0) = 0.5 * kSpeedMps * (1.0 - std::cos(w * t));
      qdd(0) = 0.5 * kSpeedMps * w * std::sin(w * t);
    } else {
      q(0) += 0.5 * kSpeedMps * kRampS + kSpeedMps * (t - kRampS);
      qd(0) = kSpeedMps;
    }
    const UpdateResult r = StepLevelAlongX(c, truth, k, kArm, q, qd, qdd, &ekf);
    if (r.Has(kEventDiverged)) ++run.divergences;
    if (k >= kCruiseFrom && r.has_estimate) {
      run.worst_xd_error_mps =
          std::max(run.worst_xd_error_mps, std::fabs(ekf.estimate().qd(0) - qd(0)));
    }
  }
  std::printf(
      "[geometry tilt] initial bias std %.2f m/s^2: %d restarts, cruising |xd error| <= "
      "%.2f mm/s, bias estimate (%.4f %.4f %.4f) m/s^2\n",
      initial_bias_std_mps2, run.divergences, run.worst_xd_error_mps * 1e3,
      ekf.estimate().accel_bias_mps2.x(), ekf.estimate().accel_bias_mps2.y(),
      ekf.estimate().accel_bias_mps2.z());
  return run;
}

TEST(EkfGeometryTilt, AWrongGeometrysTiltIsTakenAsAnAccelerometerBiasNotAVelocity) {
  const StackConfig& c = DefaultStackConfig();
  ASSERT_GT(c.estimator.initial_accel_bias_std_mps2, 0.0) << "the shipped config estimates b_a";
  double pitch_error_rad = 0.0;
  const PlatformParams truth = TiltingGeometry(c, &pitch_error_rad);
  std::printf("[geometry tilt] the legs tilt the pose by %.2f mrad in pitch\n",
              pitch_error_rad * 1e3);

  const TiltRun shipped = RunCruise(truth, c.estimator.initial_accel_bias_std_mps2);
  EXPECT_EQ(shipped.divergences, 0);
  EXPECT_LT(shipped.worst_xd_error_mps, 0.5e-3);

  // Without the state the same geometry holds the velocity estimate off.
  const TiltRun without = RunCruise(truth, 0.0);
  EXPECT_GT(without.worst_xd_error_mps, 1.5e-3);
}

struct SweepRun {
  int divergences = 0;
  int legs_gated = 0;
  double worst_xd_error_mps = 0.0;         ///< once armed and settled
  double worst_rate_error_radps = 0.0;     ///< the Euler rates, likewise
  double attitude_error_change_rad = 0.0;  ///< of the legs' pose along the sweep
  double legs_xd_error_mps = 0.0;          ///< of the legs' pose's rate: d/dt LegPoseError
  double legs_rate_error_radps = 0.0;      ///< likewise, the Euler rates
};

// The pose the model's geometry gives for the truth's leg lengths at q,
// less q: what the legs tell the estimator about the pose.
Vector6d LegPoseError(const PlatformParams& model, const PlatformParams& truth, const Vector6d& q) {
  return ForwardKinematics(model, InverseKinematics(truth, q), q).q - q;
}

// Level platform swept along x from +90 mm to -90 mm and back, each way a
// minimum-jerk move of 1.5 s (0.22 m/s at the centre: the speeds the random
// campaign reaches along a direction without a limit), after 0.5 s armed at
// rest. The legs' attitude error moves by some mrad on the way while the
// gyro reads the true rates (zero), so the two part at a few mrad/s.
SweepRun RunSweep(const PlatformParams& truth, double gyro_walk_per_speed,
                  double accel_walk_per_speed) {
  StackConfig c = DefaultStackConfig();
  c.estimator.gyro_bias_walk_per_speed = gyro_walk_per_speed;
  c.estimator.accel_bias_walk_per_speed = accel_walk_per_speed;
  Ekf ekf(c.platform, c.actuators, c.sensors, c.estimator, c.home_pose);
  constexpr double kAmplitudeM = 0.09, kMoveS = 1.5;
  constexpr int kArm = 500, kSweep = 1000, kMoveSamples = 1500,
                kEnd = kSweep + 2 * kMoveSamples + 500;
  const Vector6d start_error =
      LegPoseError(c.platform, truth, c.home_pose + kAmplitudeM * Vector6d::Unit(0));
  SweepRun run;
  for (int k = 0; k < kEnd; ++k) {
    // Minimum jerk: s(tau) = 10 tau^3 - 15 tau^4 + 6 tau^5 from 0 to 1.
    const int j = std::clamp(k - kSweep, 0, 2 * kMoveSamples);
    const bool back = j > kMoveSamples;
    const double tau = static_cast<double>(back ? j - kMoveSamples : j) / kMoveSamples;
    const double pos = tau * tau * tau * (10.0 - 15.0 * tau + 6.0 * tau * tau);
    const double vel = 30.0 * tau * tau * (1.0 - tau) * (1.0 - tau) / kMoveS;
    const double acc = 60.0 * tau * (1.0 - tau) * (1.0 - 2.0 * tau) / (kMoveS * kMoveS);
    const double dir = back ? 1.0 : -1.0;  // +A -> -A, then back
    Vector6d q = c.home_pose, qd = Vector6d::Zero(), qdd = Vector6d::Zero();
    q(0) += back ? -kAmplitudeM + 2.0 * kAmplitudeM * pos : kAmplitudeM - 2.0 * kAmplitudeM * pos;
    qd(0) = dir * 2.0 * kAmplitudeM * vel;
    qdd(0) = dir * 2.0 * kAmplitudeM * acc;
    const UpdateResult r = StepLevelAlongX(c, truth, k, kArm, q, qd, qdd, &ekf);
    if (r.Has(kEventDiverged)) ++run.divergences;
    if (r.Has(kGateLegs)) ++run.legs_gated;
    if (k >= kSweep && r.has_estimate) {
      const Vector6d qd_error = ekf.estimate().qd - qd;
      run.worst_xd_error_mps = std::max(run.worst_xd_error_mps, std::fabs(qd_error(0)));
      run.worst_rate_error_radps =
          std::max(run.worst_rate_error_radps, qd_error.tail<3>().cwiseAbs().maxCoeff());
    }
    if (k % 10 == 0) {
      const Vector6d error = LegPoseError(c.platform, truth, q);
      run.attitude_error_change_rad = std::max(
          run.attitude_error_change_rad, (error - start_error).tail<3>().cwiseAbs().maxCoeff());
      // What the legs say of the velocity differs from the truth by the
      // error's rate, which no estimator of the model's geometry can see.
      const Vector6d error_rate = (LegPoseError(c.platform, truth, q + 1e-4 * qd) - error) / 1e-4;
      run.legs_xd_error_mps = std::max(run.legs_xd_error_mps, std::fabs(error_rate(0)));
      run.legs_rate_error_radps =
          std::max(run.legs_rate_error_radps, error_rate.tail<3>().cwiseAbs().maxCoeff());
    }
  }
  std::printf(
      "[geometry sweep] bias walks per speed: gyro %.0e, accelerometer %.0e: %d restarts, %d leg "
      "samples gated; "
      "worst |xd error| %.2f mm/s, |rate error| %.2f mrad/s; the legs' attitude error moves by "
      "%.2f mrad, their pose's rate is off by up to %.2f mm/s in x, %.2f mrad/s in angle\n",
      gyro_walk_per_speed, accel_walk_per_speed, run.divergences, run.legs_gated,
      run.worst_xd_error_mps * 1e3, run.worst_rate_error_radps * 1e3,
      run.attitude_error_change_rad * 1e3, run.legs_xd_error_mps * 1e3,
      run.legs_rate_error_radps * 1e3);
  return run;
}

// The attitude error moving under the gyro reads, to the EKF, as a gyro bias
// that changes while the platform moves. With only the walk of a still
// gyro's bias (1e-5 rad/s/sqrt(s)) the estimate cannot follow: the legs are
// gated and it restarts (8 random campaign runs of 1000, the bounds without
// pushes, did so at 0.08-0.18 m/s); the shipped walk per speed lets b_g take
// the difference.
TEST(EkfGeometryTilt, AWrongGeometrySweptAtSpeedIsFollowedWithoutARestart) {
  const StackConfig& c = DefaultStackConfig();
  double pitch_error_rad = 0.0;
  const PlatformParams truth = TiltingGeometry(c, &pitch_error_rad);
  const SweepRun before = RunSweep(truth, 0.0, 0.0);
  EXPECT_GT(before.attitude_error_change_rad, 3e-3) << "a geometry whose tilt moves";
  EXPECT_GT(before.divergences, 0);

  ASSERT_GT(c.estimator.gyro_bias_walk_per_speed, 0.0);
  const SweepRun shipped =
      RunSweep(truth, c.estimator.gyro_bias_walk_per_speed, c.estimator.accel_bias_walk_per_speed);
  EXPECT_EQ(shipped.divergences, 0);
  EXPECT_EQ(shipped.legs_gated, 0);
  // The velocity within 2 % of the sweep's top speed (0.22 m/s; at the
  // limits' 15 mm/s that is 0.3 mm/s), the rates between the gyro's (true)
  // and what the legs' moving error says.
  EXPECT_LT(shipped.worst_xd_error_mps, 0.02 * 0.22);
  EXPECT_LT(shipped.worst_rate_error_radps, shipped.legs_rate_error_radps);
}

// The same tilt against the accelerometer: the share of gravity it reads
// against the estimate's attitude changes along the sweep faster than the
// bias's walk at rest (1e-3 m/s^2/sqrt(s)) follows, and what b_a cannot take
// the velocity does. The shipped walk per speed lets b_a follow.
TEST(EkfGeometryTilt, TheAccelerometersBiasFollowsAWrongGeometrysTiltAtSpeed) {
  const StackConfig& c = DefaultStackConfig();
  double pitch_error_rad = 0.0;
  const PlatformParams truth = TiltingGeometry(c, &pitch_error_rad);
  ASSERT_GT(c.estimator.accel_bias_walk_per_speed, 0.0);
  const SweepRun without = RunSweep(truth, c.estimator.gyro_bias_walk_per_speed, 0.0);
  const SweepRun shipped =
      RunSweep(truth, c.estimator.gyro_bias_walk_per_speed, c.estimator.accel_bias_walk_per_speed);
  EXPECT_EQ(shipped.divergences, 0);
  EXPECT_LT(shipped.worst_xd_error_mps, 0.6 * without.worst_xd_error_mps);
}

}  // namespace
}  // namespace stewart
