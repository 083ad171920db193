// HOLD through the safety process: the safe stop brakes for
// supervisor.hold_brake_s of stack time, then the actuators are turned off
// (the lead screws hold), until the operator resumes.
#include <gtest/gtest.h>

#include "safety_test_support.h"
#include "stewart/common/health_counters.h"
#include "stewart/safety/safety_process.h"

namespace stewart::safety::test {
namespace {

TEST(SafetyProcessHold, BrakesThenTurnsTheDriveOff) {
  const StackConfig& c = DefaultConfig();
  SupervisorConfig supervisor;
  supervisor.auto_arm = true;
  supervisor.arming_ramp_s = 0.0;
  supervisor.fallback_latch_s = 0.02;
  supervisor.hold_brake_s = 0.1;
  HealthCounters counters("safety hold test");
  SafetyProcess process(c.platform, c.safety, c.actuators, supervisor, nullptr, &counters);
  const Vector6d q = c.home_pose;
  const Vector6d hover_n = HoverForce(q);
  // 50 ms armed with a nominal command per state, then the controller silent.
  int64_t hold_from_utime = -1, locked_from_utime = -1;
  for (int k = 0; k < 400; ++k) {
    StateSample state;
    state.utime = state.sample_utime = 1'000'000 + 1000 * static_cast<int64_t>(k);
    state.seq = k;
    state.q = q;
    state.status = kStateValid;
    SafetyOutput out;
    const bool answered = process.OnState(state, &out);
    if (k < 50) {
      ForceCommand nominal;
      nominal.utime = nominal.sample_utime = state.sample_utime;
      nominal.seq = k;
      nominal.force_n = hover_n;
      ASSERT_TRUE(answered || process.OnNominal(nominal, &out)) << k;
      if (k > 0) {
        ASSERT_EQ(out.mode.state, SupervisorState::kArmed) << k;
      }
      continue;
    }
    // The watchdog answers a silent controller once its nominal is stale.
    if (!answered) continue;
    const bool drive_off = (out.command.flags & kCommandDriveOff) != 0;
    if (out.mode.state != SupervisorState::kHold) {
      EXPECT_FALSE(drive_off) << k;  // the fallback before the latch
      continue;
    }
    if (hold_from_utime < 0) hold_from_utime = state.utime;
    if (!drive_off) {
      EXPECT_LT(locked_from_utime, 0) << "the drive came back on by itself at " << k;
      // Braking at rest: the safe stop carries the platform's weight.
      EXPECT_LT((out.command.force_n - hover_n).cwiseAbs().maxCoeff(), 1e-9) << k;
      EXPECT_TRUE(out.command.flags & kCommandFallback) << k;
    } else {
      if (locked_from_utime < 0) locked_from_utime = state.utime;
      EXPECT_EQ(out.command.force_n, Vector6d::Zero()) << k;
    }
  }
  ASSERT_GT(hold_from_utime, 0) << "never held";
  ASSERT_GT(locked_from_utime, 0) << "the drive never went off in HOLD";
  EXPECT_EQ(locked_from_utime - hold_from_utime, 100'000);
}

}  // namespace
}  // namespace stewart::safety::test
