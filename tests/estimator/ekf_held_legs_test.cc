// DC-motor legs without drive are held by their self-locking screws: the EKF
// predicts them held, so a platform at rest under a zero command (the safe
// stop) or no command at all keeps a zero velocity and does not invent a
// model error d that the controller and the filter would then apply.
#include <gtest/gtest.h>

#include <cstdio>

#include "stewart/config/default_config.h"
#include "stewart/estimator/ekf.h"
#include "stewart/model/kinematics.h"

namespace stewart {
namespace {

struct HeldRun {
  Vector6d qd = Vector6d::Zero();
  Vector6d d = Vector6d::Zero();
  int held_samples = 0;
  int diverged = 0;
};

// 2 s at rest at home with noise-free readings; `command` each sample (or
// none when `with_command` is false).
HeldRun RunAtRest(const StackConfig& c, bool with_command, const Vector6d& command_n,
                  bool samples_say_drive_off = false) {
  Ekf ekf(c.platform, c.actuators, c.sensors, c.estimator, c.home_pose);
  SensorSample sample;
  sample.drive_off = samples_say_drive_off;
  sample.leg_length_m = InverseKinematics(c.platform, c.home_pose);
  sample.accel_mps2 = Vector3d(0.0, 0.0, c.platform.gravity_mps2);  // specific force at rest
  sample.gyro_radps = c.sensors.gyro_bias_radps;
  HeldRun run;
  for (int k = 0; k < 2000; ++k) {
    sample.utime = 1'000'000 + 1000 * static_cast<int64_t>(k);
    const UpdateResult r = ekf.Update(sample);
    if (r.Has(kEventLegsHeld)) ++run.held_samples;
    if (r.Has(kEventDiverged)) ++run.diverged;
    if (with_command) ekf.SetForceCommand(sample.utime, command_n);
  }
  run.qd = ekf.estimate().qd;
  run.d = ekf.estimate().disturbance_n;
  return run;
}

TEST(EkfHeldLegs, ZeroDriveAtRestKeepsVelocityAndModelErrorAtZero) {
  const StackConfig& c = DcMotorStackConfig();
  ASSERT_EQ(c.actuators.kind, ActuatorKind::kDcMotor);
  for (const bool with_command : {true, false}) {
    const HeldRun run = RunAtRest(c, with_command, Vector6d::Zero());
    EXPECT_GT(run.held_samples, 1990) << with_command;
    EXPECT_EQ(run.diverged, 0);
    EXPECT_LT(run.qd.cwiseAbs().maxCoeff(), 1e-5) << run.qd.transpose();
    // The weight is 8 N: a dynamics model with F = 0 explains the legs'
    // stillness with d of that size.
    EXPECT_LT(run.d.head<3>().cwiseAbs().maxCoeff(), 0.5) << run.d.transpose();
  }
}

// With the drive on, the dynamics model predicts: a hovering command at rest
// is not "held", and d stays near zero because the command carries the weight.
TEST(EkfHeldLegs, HoverCommandUsesTheDynamics) {
  const StackConfig& c = DcMotorStackConfig();
  const Vector6d hover_n = InverseDynamics(
      EvaluateDynamics(c.platform, c.home_pose, Vector6d::Zero()), Vector6d::Zero());
  const HeldRun run = RunAtRest(c, true, hover_n);
  EXPECT_LE(run.held_samples, 1);  // the first prediction has no command yet
  EXPECT_EQ(run.diverged, 0);
  EXPECT_LT(run.d.head<3>().cwiseAbs().maxCoeff(), 0.5) << run.d.transpose();
}

// The ideal force source is never held by itself: with F = 0 the platform
// falls, and the estimator must not pretend otherwise.
TEST(EkfHeldLegs, IdealForceSourceIsNeverHeld) {
  const HeldRun run = RunAtRest(DefaultStackConfig(), true, Vector6d::Zero());
  EXPECT_EQ(run.held_samples, 0);
}

// The actuators refused the safe commands (plant_sim's command timeout, the
// device's watchdog) and the samples say so: the legs are held whatever the
// commands, so d does not absorb a push that never acted. Before, d grew to
// explain the stillness, and the controller applied it when the drive came
// back.
TEST(EkfHeldLegs, SamplesWithoutDriveAreHeldWhateverTheCommands) {
  const StackConfig& c = DefaultStackConfig();
  const Vector6d hover_n = InverseDynamics(
      EvaluateDynamics(c.platform, c.home_pose, Vector6d::Zero()), Vector6d::Zero());
  const Vector6d push_n = hover_n + Vector6d::Constant(3.0);
  const HeldRun said = RunAtRest(c, true, push_n, /*samples_say_drive_off=*/true);
  EXPECT_GT(said.held_samples, 1990);
  EXPECT_LT(said.qd.cwiseAbs().maxCoeff(), 1e-5) << said.qd.transpose();
  EXPECT_LT(said.d.head<3>().cwiseAbs().maxCoeff(), 0.5) << said.d.transpose();
  // Without the word, the push is predicted and d takes it up.
  const HeldRun unsaid = RunAtRest(c, true, push_n, false);
  EXPECT_EQ(unsaid.held_samples, 0);
  EXPECT_GT(unsaid.d.head<3>().cwiseAbs().maxCoeff(), 1.0) << unsaid.d.transpose();
  std::printf("[held-legs] max |d| (x, y, z) after 2 s held: %.3f N said, %.3f N unsaid\n",
              said.d.head<3>().cwiseAbs().maxCoeff(), unsaid.d.head<3>().cwiseAbs().maxCoeff());
}

}  // namespace
}  // namespace stewart
