// Joint centres that are not where the config says (within the bounds the
// stack is measured in: +-1 mm radius, +-0.5 deg angle per joint) tilt the
// pose the legs give by some mrad, while the accelerometer sees the true
// gravity direction. The EKF must not settle that disagreement with a wrong
// velocity (the safety filter keeps the velocity estimate, not the truth,
// below its limit): read in the platform frame it is a bias of the
// accelerometer, which the state b_a takes (docs/estimator.md, "The
// accelerometer's bias").
#include <gtest/gtest.h>

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
    SensorSample s;
    s.utime = 1'000'000 + 1000 * static_cast<int64_t>(k);
    s.drive_off = k < kArm;
    s.leg_length_m = InverseKinematics(truth, q);
    s.accel_mps2 = Vector3d(qdd(0), 0.0, c.platform.gravity_mps2);  // level: {P} = {B}
    s.gyro_radps = c.sensors.gyro_bias_radps;
    const UpdateResult r = ekf.Update(s);
    if (r.Has(kEventDiverged)) ++run.divergences;
    const Vector6d force_n = InverseDynamics(EvaluateDynamics(truth, q, qd), qdd);
    ekf.SetForceCommand(s.utime, k < kArm ? Vector6d::Zero() : force_n, k < kArm);
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

}  // namespace
}  // namespace stewart
