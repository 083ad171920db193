// The supervisor's transitions (safety/supervisor.h) and the heartbeat
// monitor (safety/process_monitor.h), without LCM.
#include "stewart/safety/supervisor.h"

#include <gtest/gtest.h>

#include "stewart/safety/process_monitor.h"

namespace stewart::safety::test {
namespace {

constexpr int64_t kPeriodUs = 1000;

SupervisorStep Good(int64_t k) {
  SupervisorStep s;
  s.utime = s.sample_utime = k * kPeriodUs;
  s.state_usable = s.limits_allow_arming = s.filtered = true;
  return s;
}

SupervisorConfig Config(double ramp_s = 0.01) {
  SupervisorConfig c;
  c.arming_ramp_s = ramp_s;
  c.fallback_latch_s = 0.0;  // the first fallback while moving latches
  return c;
}

bool Do(Supervisor* s, OperatorCommand c, std::string* why = nullptr, bool healthy = true) {
  std::string rejection;
  const bool ok = s->OnOperator(c, healthy, "no healthy heartbeat from estimator", &rejection);
  if (why != nullptr) *why = rejection;
  return ok;
}

TEST(Supervisor, PowerOnIsDisarmedWithTheDriveOff) {
  Supervisor s(Config());
  for (int64_t k = 0; k < 100; ++k) {
    const SupervisorMode m = s.OnStep(Good(k));
    EXPECT_EQ(m.state, SupervisorState::kDisarmed);
    EXPECT_TRUE(m.drive_off());
  }
  EXPECT_EQ(s.motion_time_us(), 0);
}

TEST(Supervisor, ArmRampsFromTheHoldToTheFilteredCommand) {
  Supervisor s(Config(0.01));
  s.OnStep(Good(0));
  ASSERT_TRUE(Do(&s, OperatorCommand::kArm));
  EXPECT_EQ(s.state(), SupervisorState::kArming);
  double last_blend = -1.0;
  int64_t k = 1;
  for (; s.state() == SupervisorState::kArming; ++k) {
    const SupervisorMode m = s.OnStep(Good(k));
    EXPECT_FALSE(m.drive_off());
    EXPECT_GE(m.blend, last_blend);
    EXPECT_LE(m.blend - std::max(last_blend, 0.0), 0.1 + 1e-12);  // 1 ms of a 10 ms ramp
    last_blend = m.blend;
    ASSERT_LT(k, 100);
  }
  EXPECT_EQ(s.state(), SupervisorState::kArmed);
  EXPECT_DOUBLE_EQ(s.blend(), 1.0);
  EXPECT_EQ(k, 12);  // the ramp starts at the first step after arm: 10 ms later it is done
}

TEST(Supervisor, ArmIsRefusedUnlessEverythingIsReady) {
  Supervisor s(Config());
  std::string why;
  EXPECT_FALSE(Do(&s, OperatorCommand::kArm, &why));
  EXPECT_NE(why.find("no state estimate"), std::string::npos) << why;
  SupervisorStep step = Good(0);
  step.state_usable = false;
  s.OnStep(step);
  EXPECT_FALSE(Do(&s, OperatorCommand::kArm, &why));
  EXPECT_NE(why.find("not usable"), std::string::npos) << why;
  step = Good(1);
  step.limits_allow_arming = false;
  s.OnStep(step);
  EXPECT_FALSE(Do(&s, OperatorCommand::kArm, &why));
  EXPECT_NE(why.find("outside its limits"), std::string::npos) << why;
  step = Good(2);
  step.filtered = false;
  s.OnStep(step);
  EXPECT_FALSE(Do(&s, OperatorCommand::kArm, &why));
  EXPECT_NE(why.find("controller"), std::string::npos) << why;
  s.OnStep(Good(3));
  EXPECT_FALSE(Do(&s, OperatorCommand::kArm, &why, /*healthy=*/false));
  EXPECT_NE(why.find("heartbeat"), std::string::npos) << why;
  EXPECT_EQ(s.state(), SupervisorState::kDisarmed);
  EXPECT_TRUE(Do(&s, OperatorCommand::kArm));
}

TEST(Supervisor, AFallbackWhileArmedLatchesHoldUntilResetAndResume) {
  Supervisor s(Config(0.0));
  s.OnStep(Good(0));
  ASSERT_TRUE(Do(&s, OperatorCommand::kArm));
  s.OnStep(Good(1));
  ASSERT_EQ(s.state(), SupervisorState::kArmed);
  SupervisorStep stale = Good(2);
  stale.filtered = false;  // the controller went quiet: the watchdog's fallback
  EXPECT_EQ(s.OnStep(stale).state, SupervisorState::kHold);
  EXPECT_TRUE(s.fault_latched());
  EXPECT_NE(s.reason().find("controller"), std::string::npos) << s.reason();
  // The controller is back: nothing moves by itself.
  for (int64_t k = 3; k < 1000; ++k) EXPECT_EQ(s.OnStep(Good(k)).state, SupervisorState::kHold);
  std::string why;
  EXPECT_FALSE(Do(&s, OperatorCommand::kResume, &why));
  EXPECT_NE(why.find("reset first"), std::string::npos) << why;
  EXPECT_TRUE(Do(&s, OperatorCommand::kReset));
  EXPECT_EQ(s.state(), SupervisorState::kHold);
  EXPECT_FALSE(s.fault_latched());
  EXPECT_TRUE(Do(&s, OperatorCommand::kResume));
  EXPECT_EQ(s.state(), SupervisorState::kArming);
}

TEST(Supervisor, AStateThatWaitedLongerThanTheLatchIsAStallWhileMoving) {
  SupervisorConfig c = Config(0.0);
  c.fallback_latch_s = 0.1;
  Supervisor s(c);
  s.OnStep(Good(0));
  // Not moving: nothing to hold.
  EXPECT_EQ(s.InputWaitFault(2'000'000), "");
  ASSERT_TRUE(Do(&s, OperatorCommand::kArm));
  s.OnStep(Good(1));
  ASSERT_EQ(s.state(), SupervisorState::kArmed);
  EXPECT_EQ(s.InputWaitFault(100'000), "");
  const std::string stalled = s.InputWaitFault(100'001);
  EXPECT_NE(stalled.find("stalled"), std::string::npos) << stalled;
  s.OnFault(stalled);
  EXPECT_EQ(s.state(), SupervisorState::kHold);
  EXPECT_EQ(s.InputWaitFault(2'000'000), "");
}

// Lockstep simulation: the plant waits for the command, so a late read
// stalls nothing (tools/launch.sh sets stall_check false there).
TEST(Supervisor, WithoutTheStallCheckAWaitIsNoFault) {
  SupervisorConfig c = Config(0.0);
  c.fallback_latch_s = 0.1;
  c.stall_check = false;
  Supervisor s(c);
  s.OnStep(Good(0));
  ASSERT_TRUE(Do(&s, OperatorCommand::kArm));
  s.OnStep(Good(1));
  ASSERT_EQ(s.state(), SupervisorState::kArmed);
  EXPECT_EQ(s.InputWaitFault(2'000'000), "");
  EXPECT_EQ(s.state(), SupervisorState::kArmed);
}

TEST(Supervisor, ALatchOfZeroDoesNotMakeEveryWaitAStall) {
  SupervisorConfig c = Config(0.0);
  c.fallback_latch_s = 0.0;  // every lasting fallback latches at once
  Supervisor s(c);
  s.OnStep(Good(0));
  ASSERT_TRUE(Do(&s, OperatorCommand::kArm));
  s.OnStep(Good(1));
  ASSERT_EQ(s.state(), SupervisorState::kArmed);
  EXPECT_EQ(s.InputWaitFault(50), "") << "a scheduling delay of 50 us";
  EXPECT_EQ(s.InputWaitFault(100'000), "");
  EXPECT_NE(s.InputWaitFault(100'001).find("stalled"), std::string::npos);
}

TEST(Supervisor, ShortFallbacksGoOnLastingOnesLatch) {
  SupervisorConfig c = Config(0.0);
  c.fallback_latch_s = 0.05;
  Supervisor s(c);
  s.OnStep(Good(0));
  ASSERT_TRUE(Do(&s, OperatorCommand::kArm));
  int64_t k = 1;
  for (; k < 10; ++k) s.OnStep(Good(k));
  // 49 ms of fallbacks: still armed (each of those steps got the safe stop).
  for (const int64_t end = k + 50; k < end; ++k) {
    SupervisorStep stale = Good(k);
    stale.filtered = false;
    EXPECT_EQ(s.OnStep(stale).state, SupervisorState::kArmed) << k;
  }
  EXPECT_EQ(s.OnStep(Good(k++)).state, SupervisorState::kArmed);
  // 50 ms: latched.
  SupervisorMode m;
  for (const int64_t end = k + 51; k < end; ++k) {
    SupervisorStep stale = Good(k);
    stale.filtered = false;
    m = s.OnStep(stale);
  }
  EXPECT_EQ(m.state, SupervisorState::kHold);
  EXPECT_TRUE(s.fault_latched());
}

TEST(Supervisor, OperatorHoldNeedsNoReset) {
  Supervisor s(Config(0.0));
  s.OnStep(Good(0));
  ASSERT_TRUE(Do(&s, OperatorCommand::kArm));
  s.OnStep(Good(1));
  ASSERT_TRUE(Do(&s, OperatorCommand::kHold));
  EXPECT_EQ(s.state(), SupervisorState::kHold);
  EXPECT_FALSE(s.fault_latched());
  s.OnStep(Good(2));
  EXPECT_TRUE(Do(&s, OperatorCommand::kResume));
}

// HOLD brakes (the safe stop, drive on) for hold_brake_s of stack time from
// its first step, then turns the drive off (the lead screws hold) until the
// operator resumes; resume ramps with the drive on again.
TEST(Supervisor, HoldBrakesThenTurnsTheDriveOff) {
  SupervisorConfig c = Config(0.0);
  c.hold_brake_s = 0.05;
  Supervisor s(c);
  s.OnStep(Good(0));
  ASSERT_TRUE(Do(&s, OperatorCommand::kArm));
  s.OnStep(Good(1));
  ASSERT_EQ(s.state(), SupervisorState::kArmed);
  ASSERT_TRUE(Do(&s, OperatorCommand::kHold));
  int64_t k = 2;
  for (; k < 2 + 50; ++k) {
    const SupervisorMode m = s.OnStep(Good(k));
    EXPECT_EQ(m.state, SupervisorState::kHold);
    EXPECT_FALSE(m.drive_off()) << "braking, at step " << k;
  }
  for (; k < 200; ++k) {
    const SupervisorMode m = s.OnStep(Good(k));
    EXPECT_EQ(m.state, SupervisorState::kHold);
    EXPECT_TRUE(m.hold_locked);
    EXPECT_TRUE(m.drive_off()) << "still braking, at step " << k;
  }
  ASSERT_TRUE(Do(&s, OperatorCommand::kResume));
  EXPECT_FALSE(s.OnStep(Good(k++)).drive_off());
  // A second HOLD brakes again from its own first step.
  ASSERT_TRUE(Do(&s, OperatorCommand::kHold));
  EXPECT_FALSE(s.OnStep(Good(k++)).drive_off());
  // Brake only: HOLD never turns the drive off.
  c.hold_drive_off = false;
  Supervisor brake_only(c);
  brake_only.OnStep(Good(0));
  ASSERT_TRUE(Do(&brake_only, OperatorCommand::kArm));
  ASSERT_TRUE(Do(&brake_only, OperatorCommand::kHold));
  for (k = 1; k < 200; ++k) EXPECT_FALSE(brake_only.OnStep(Good(k)).drive_off());
}

TEST(Supervisor, EstopLatchesFromAnyStateAndResetDisarms) {
  for (const bool armed : {false, true}) {
    Supervisor s(Config(0.0));
    s.OnStep(Good(0));
    if (armed) {
      ASSERT_TRUE(Do(&s, OperatorCommand::kArm));
    }
    ASSERT_TRUE(Do(&s, OperatorCommand::kEstop));
    for (int64_t k = 1; k < 50; ++k) EXPECT_TRUE(s.OnStep(Good(k)).drive_off());
    std::string why;
    EXPECT_FALSE(Do(&s, OperatorCommand::kArm, &why));
    EXPECT_FALSE(Do(&s, OperatorCommand::kResume, &why));
    EXPECT_EQ(s.state(), SupervisorState::kEstop);
    EXPECT_TRUE(Do(&s, OperatorCommand::kReset));
    EXPECT_EQ(s.state(), SupervisorState::kDisarmed);
  }
}

TEST(Supervisor, OutsideFaultsHoldWhenMovingAndBlockArmingUntilReset) {
  Supervisor s(Config(0.0));
  s.OnStep(Good(0));
  s.OnFault("controller restarted");
  EXPECT_EQ(s.state(), SupervisorState::kDisarmed);
  std::string why;
  EXPECT_FALSE(Do(&s, OperatorCommand::kArm, &why));
  EXPECT_NE(why.find("controller restarted"), std::string::npos) << why;
  ASSERT_TRUE(Do(&s, OperatorCommand::kReset));
  ASSERT_TRUE(Do(&s, OperatorCommand::kArm));
  s.OnStep(Good(1));
  s.OnFault("estimator heartbeat lost");
  EXPECT_EQ(s.state(), SupervisorState::kHold);
  EXPECT_NE(s.reason().find("estimator heartbeat lost"), std::string::npos);
}

TEST(Supervisor, MotionClockRunsOnlyWhileMoving) {
  Supervisor s(Config(0.0));
  for (int64_t k = 0; k < 10; ++k) s.OnStep(Good(k));
  ASSERT_TRUE(Do(&s, OperatorCommand::kArm));
  for (int64_t k = 10; k < 110; ++k) s.OnStep(Good(k));
  EXPECT_EQ(s.motion_time_us(), 100 * kPeriodUs);
  ASSERT_TRUE(Do(&s, OperatorCommand::kHold));
  for (int64_t k = 110; k < 500; ++k) s.OnStep(Good(k));
  EXPECT_EQ(s.motion_time_us(), 100 * kPeriodUs);  // paused while held
  ASSERT_TRUE(Do(&s, OperatorCommand::kResume));
  for (int64_t k = 500; k < 550; ++k) s.OnStep(Good(k));
  EXPECT_EQ(s.motion_time_us(), 150 * kPeriodUs);
}

TEST(Supervisor, AutoArmArmsAtTheFirstArmableStepOnly) {
  SupervisorConfig c = Config(0.0);
  c.auto_arm = true;
  Supervisor s(c);
  SupervisorStep not_yet = Good(0);
  not_yet.state_usable = false;
  EXPECT_EQ(s.OnStep(not_yet).state, SupervisorState::kDisarmed);
  EXPECT_EQ(s.OnStep(Good(1)).state, SupervisorState::kArmed);
  // A fault still latches; auto-arm does not resume.
  SupervisorStep stale = Good(2);
  stale.filtered = false;
  EXPECT_EQ(s.OnStep(stale).state, SupervisorState::kHold);
  for (int64_t k = 3; k < 100; ++k) EXPECT_EQ(s.OnStep(Good(k)).state, SupervisorState::kHold);
}

TEST(ProcessMonitor, RequiredProcessesAlternativesRestartsFaultsAndSilence) {
  ProcessMonitor m({"estimator", "controller", "plant_sim|hw_bridge"}, 1'000'000);
  std::string why;
  EXPECT_FALSE(m.Healthy(0, &why));
  EXPECT_NE(why.find("estimator"), std::string::npos);
  EXPECT_EQ(m.OnHeartbeat("estimator", 1, 0, 0), "");
  EXPECT_EQ(m.OnHeartbeat("controller", 1, 0, 0), "");
  EXPECT_FALSE(m.Healthy(0, &why));
  EXPECT_NE(why.find("plant_sim or hw_bridge"), std::string::npos) << why;
  EXPECT_EQ(m.OnHeartbeat("hw_bridge", 1, 0, 0), "");
  EXPECT_TRUE(m.Healthy(0, &why));
  EXPECT_EQ(m.OnHeartbeat("logger", 3, 0, 0), "");  // not required: ignored
  // Restart: the sequence starts over.
  EXPECT_EQ(m.OnHeartbeat("controller", 1, 5, 100), "");
  EXPECT_EQ(m.OnHeartbeat("controller", 1, 0, 200), "controller restarted");
  EXPECT_EQ(m.OnHeartbeat("estimator", 3, 1, 300), "estimator reported FAULT");
  EXPECT_EQ(m.OnHeartbeat("estimator", 3, 2, 400), "");  // reported once
  EXPECT_FALSE(m.Healthy(400, &why));
  EXPECT_EQ(m.OnHeartbeat("estimator", 1, 3, 500), "");
  EXPECT_TRUE(m.Healthy(500, &why));
  // Silence, reported once per silence.
  EXPECT_EQ(m.OnHeartbeat("estimator", 1, 4, 1'200'000), "");
  EXPECT_EQ(m.OnHeartbeat("controller", 1, 1, 1'200'000), "");
  const std::vector<std::string> silent = m.CheckSilence(1'300'000);
  ASSERT_EQ(silent.size(), 1u);  // hw_bridge: last heard at 0
  EXPECT_EQ(silent[0], "hw_bridge heartbeat lost");
  EXPECT_TRUE(m.CheckSilence(1'400'000).empty());
  EXPECT_FALSE(m.Healthy(1'300'000, &why));
}

// A process never heard from at all (stopped before its first heartbeat, or
// its first missed while safety started) is silent too once the platform
// has moved for the timeout; before, it was never judged, and an auto-armed
// platform relied on the nominal watchdog alone.
TEST(ProcessMonitor, ARequirementNeverHeardFromIsSilentOnceMoving) {
  ProcessMonitor m({"estimator", "controller", "plant_sim|hw_bridge"}, 1'000'000);
  EXPECT_EQ(m.OnHeartbeat("estimator", 1, 0, 0), "");
  EXPECT_EQ(m.OnHeartbeat("plant_sim", 1, 0, 0), "");
  EXPECT_TRUE(m.CheckSilence(5'000'000).size() == 2u);  // both seen at 0: lost
  m.SetMoving(true, 5'000'000);
  EXPECT_EQ(m.OnHeartbeat("estimator", 1, 1, 5'500'000), "");
  EXPECT_EQ(m.OnHeartbeat("plant_sim", 1, 1, 5'500'000), "");
  EXPECT_TRUE(m.CheckSilence(5'900'000).empty());  // moving for less than the timeout
  const std::vector<std::string> unheard = m.CheckSilence(6'100'000);
  ASSERT_EQ(unheard.size(), 1u);
  EXPECT_EQ(unheard[0], "no heartbeat from controller since the platform started moving");
  EXPECT_TRUE(m.CheckSilence(6'200'000).empty());  // once
  // Held, then moving again: judged again, from the new start.
  m.SetMoving(false, 6'300'000);
  m.SetMoving(true, 7'000'000);
  for (const char* alive : {"estimator", "plant_sim"}) {
    EXPECT_EQ(m.OnHeartbeat(alive, 1, 2, 7'400'000), "");
  }
  EXPECT_TRUE(m.CheckSilence(7'500'000).empty());
  EXPECT_EQ(m.CheckSilence(8'100'000).size(), 1u);
  // Heard from: no longer.
  m.SetMoving(false, 8'200'000);
  EXPECT_EQ(m.OnHeartbeat("controller", 1, 0, 8'300'000), "");
  m.SetMoving(true, 8'300'000);
  for (const char* alive : {"estimator", "plant_sim", "controller"}) {
    EXPECT_EQ(m.OnHeartbeat(alive, 1, 3, 9'000'000), "");
  }
  EXPECT_TRUE(m.CheckSilence(9'500'000).empty());
}

}  // namespace
}  // namespace stewart::safety::test
