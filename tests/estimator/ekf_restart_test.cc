// What a restart of the estimate keeps: the model error d it has learnt. A
// payload or a wrong mass does not go away when the legs disagree for a
// while; dropping d made the next return of the drive repeat the error the
// EKF had just learnt, and restart again.
#include <gtest/gtest.h>

#include <cmath>

#include "stewart/config/default_config.h"
#include "stewart/estimator/ekf.h"
#include "stewart/model/dynamics.h"
#include "stewart/model/kinematics.h"

namespace stewart {
namespace {

// A platform at rest at home under a command that the model says lifts it by
// `extra_wrench` more than its weight: the EKF explains the stillness as
// d = -extra_wrench. Then 3 mm of leg offset for divergence_rejections samples
// restarts it from the legs.
TEST(EkfRestart, KeepsTheLearntModelErrorWithItsRotationRows) {
  StackConfig c = DefaultStackConfig();
  // The shipped config: no jumps on the rotation rows. The bound on a kept d
  // was 10 jump stds, 0 N m there: any learnt torque dropped all of d.
  c.estimator.disturbance_jump_std_nm = 0.0;
  ASSERT_TRUE(c.estimator.estimate_disturbance);
  Ekf ekf(c.platform, c.actuators, c.sensors, c.estimator, c.home_pose);
  const DynamicsTerms terms = EvaluateDynamics(c.platform, c.home_pose, Vector6d::Zero());
  Vector6d extra_wrench;
  extra_wrench << 0.2, -0.1, 1.0, 0.05, -0.03, 0.02;  // N, N m
  const Vector6d force_n =
      InverseDynamics(terms, Vector6d::Zero()) + terms.H.fullPivLu().solve(extra_wrench);
  const Vector6d legs_m = InverseKinematics(c.platform, c.home_pose);
  const int restart_from = 2000;
  const int offset_samples = c.estimator.divergence_rejections;
  Vector6d d_before = Vector6d::Zero();  // just before each update
  int restarts = 0;
  for (int k = 0; k < restart_from + offset_samples; ++k) {
    SensorSample s;
    s.utime = 1'000'000 + 1000 * static_cast<int64_t>(k);
    s.leg_length_m = legs_m;
    if (k >= restart_from) s.leg_length_m.array() += 3e-3;
    s.accel_mps2 = Vector3d(0.0, 0.0, c.platform.gravity_mps2);
    s.gyro_radps = c.sensors.gyro_bias_radps;
    // Accelerometer and gyro updates still move d while the legs are gated.
    d_before = ekf.estimate().disturbance_n;
    const UpdateResult r = ekf.Update(s);
    ASSERT_TRUE(r.has_estimate) << k;
    if (r.Has(kEventDiverged)) {
      ++restarts;
      EXPECT_EQ(k, restart_from + offset_samples - 1);
      const Estimate e = ekf.estimate();
      // The restart's sample predicts d as it was (a random walk) and its
      // accelerometer and gyro correct it after the restart.
      EXPECT_LT((e.disturbance_n - d_before).cwiseAbs().maxCoeff(), 1e-3)
          << "d dropped by the restart: " << e.disturbance_n.transpose() << " after "
          << d_before.transpose();
      // ... with its initial uncertainty.
      EXPECT_DOUBLE_EQ(e.disturbance_std_n(2), c.estimator.initial_disturbance_std_n);
      EXPECT_DOUBLE_EQ(e.disturbance_std_n(3), c.estimator.initial_disturbance_std_nm);
    }
    ekf.SetForceCommand(s.utime, force_n);
  }
  EXPECT_EQ(restarts, 1);
  // What was learnt, and kept: the extra lift cancelled, torques included.
  EXPECT_NEAR(d_before(2), -extra_wrench(2), 0.1);
  EXPECT_GT(d_before.tail<3>().cwiseAbs().maxCoeff(), 0.01);
}

// The breakdown of the arithmetic is not learnt: a d far beyond every
// configured std is dropped by the restart.
TEST(EkfRestart, DropsAModelErrorBeyondAnyConfiguredUncertainty) {
  StackConfig c = DefaultStackConfig();
  Ekf ekf(c.platform, c.actuators, c.sensors, c.estimator, c.home_pose);
  const DynamicsTerms terms = EvaluateDynamics(c.platform, c.home_pose, Vector6d::Zero());
  Vector6d extra_wrench = Vector6d::Zero();
  // 12 jump stds of lift on z, which the EKF learns (the accelerometer says
  // the platform does not move) by its jumps.
  extra_wrench(2) =
      12.0 * std::max(c.estimator.disturbance_jump_std_n, c.estimator.initial_disturbance_std_n);
  const Vector6d force_n =
      InverseDynamics(terms, Vector6d::Zero()) + terms.H.fullPivLu().solve(extra_wrench);
  const Vector6d legs_m = InverseKinematics(c.platform, c.home_pose);
  bool restarted = false;
  double d_z_learnt = 0.0;
  for (int k = 0; k < 20000 && !restarted; ++k) {
    SensorSample s;
    s.utime = 1'000'000 + 1000 * static_cast<int64_t>(k);
    s.leg_length_m = legs_m;
    if (k >= 10000) s.leg_length_m.array() += 3e-3;
    s.accel_mps2 = Vector3d(0.0, 0.0, c.platform.gravity_mps2);
    s.gyro_radps = c.sensors.gyro_bias_radps;
    if (k == 10000) d_z_learnt = ekf.estimate().disturbance_n(2);
    const UpdateResult r = ekf.Update(s);
    if (r.Has(kEventDiverged) && k >= 10000) {
      restarted = true;
      EXPECT_EQ(ekf.estimate().disturbance_n, Vector6d::Zero());
    }
    ekf.SetForceCommand(s.utime, force_n);
  }
  ASSERT_LT(d_z_learnt, -10.0 * std::max(c.estimator.disturbance_jump_std_n,
                                         c.estimator.initial_disturbance_std_n))
      << "the test needs a learnt d beyond the bound";
  EXPECT_TRUE(restarted);
}

}  // namespace
}  // namespace stewart
