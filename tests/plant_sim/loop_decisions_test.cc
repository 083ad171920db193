// The plant_sim process's decisions without sockets: which commands act
// (CommandGate), the sample-to-command latency (LoopLatencyTracker), whose
// fault a missed tick is (TickAccounting) and lockstep's resend and timeout
// (LockstepPacing) and when a real-time tick is due (RealTimePacing).
#include <gtest/gtest.h>

#include <chrono>
#include <limits>

#include "stewart/plant_sim/command_gate.h"
#include "stewart/plant_sim/lockstep_pacing.h"
#include "stewart/plant_sim/loop_latency_tracker.h"
#include "stewart/plant_sim/real_time_pacing.h"
#include "stewart/plant_sim/tick_accounting.h"

namespace stewart {
namespace {

using Clock = std::chrono::steady_clock;
using std::chrono::microseconds;
using std::chrono::milliseconds;
using Action = CommandGate::Action;

const Vector6d kForce = Vector6d::Constant(3.0);
constexpr int64_t kSession = 42;

/// A gate following session kSession, announced at `utime` (a sample the
/// gate has published).
CommandGate TrustingGate(bool lockstep, int64_t utime) {
  CommandGate gate(lockstep, SafeCommandAcceptorLimits{});
  gate.OnSamplePublished(utime);
  EXPECT_EQ(gate.OnAnnouncement({utime, 1, kSession}, true, 0), AnnouncementVerdict::kAdopted);
  return gate;
}

ForceCommand Command(int64_t sample_utime, int64_t seq, const Vector6d& force = kForce) {
  ForceCommand c;
  c.utime = c.sample_utime = sample_utime;
  c.seq = seq;
  c.force_n = force;
  c.session_id = kSession;
  return c;
}

TEST(CommandGate, NonFiniteForceIsRejectedAndNotTimed) {
  CommandGate gate = TrustingGate(false, 1000);
  Vector6d bad = kForce;
  bad(2) = std::numeric_limits<double>::quiet_NaN();
  const CommandGate::Decision d = gate.Check(Command(1000, 17, bad), true);
  EXPECT_EQ(d.action, Action::kReject);
  EXPECT_EQ(d.reason, "non_finite_force");
  EXPECT_NE(d.detail.find("force_command_t seq 17"), std::string::npos) << d.detail;
  EXPECT_FALSE(d.timed);
  EXPECT_EQ(gate.last_applied_sample_utime(), -1);
}

TEST(CommandGate, UntrustedCommandsAreRejectedAndNotTimed) {
  CommandGate gate(false, SafeCommandAcceptorLimits{});
  gate.OnSamplePublished(1000);
  CommandGate::Decision d = gate.Check(Command(1000, 1), true);
  EXPECT_EQ(d.reason, "command_no_session");
  EXPECT_FALSE(d.timed);
  ASSERT_EQ(gate.OnAnnouncement({1000, 1, kSession}, true, 0), AnnouncementVerdict::kAdopted);
  ForceCommand other = Command(1000, 2);
  other.session_id = kSession + 1;
  d = gate.Check(other, true);
  EXPECT_EQ(d.reason, "command_wrong_session");
  d = gate.Check(Command(1000, 3), false);
  EXPECT_EQ(d.reason, "command_unauthentic");
  EXPECT_FALSE(d.timed);
  EXPECT_EQ(gate.Check(Command(1000, 4), true).action, Action::kApply);
  EXPECT_EQ(gate.Check(Command(1000, 4), true).reason, "command_seq_not_increasing");
}

TEST(CommandGate, RealTimeAppliesInOrderAndRefusesFutureOlderAndStale) {
  CommandGate gate = TrustingGate(false, 2000);
  CommandGate::Decision d = gate.Check(Command(3000, 1), true);
  EXPECT_EQ(d.action, Action::kReject);
  EXPECT_EQ(d.reason, "command_future_sample");
  EXPECT_FALSE(d.timed);

  d = gate.Check(Command(2000, 2), true);
  EXPECT_EQ(d.action, Action::kApply);
  EXPECT_EQ(gate.last_applied_sample_utime(), 2000);
  d = gate.Check(Command(2000, 3), true);  // a second command for the same sample still applies
  EXPECT_EQ(d.action, Action::kApply);

  d = gate.Check(Command(1000, 4), true);
  EXPECT_EQ(d.action, Action::kReject);
  EXPECT_EQ(d.reason, "out_of_order");
  EXPECT_EQ(d.detail, "1000");
  EXPECT_EQ(gate.last_applied_sample_utime(), 2000);

  // Older than the command age limit against the newest sample: never applied.
  gate.OnSamplePublished(2000 + SafeCommandAcceptorLimits{}.command_max_age_us + 1);
  d = gate.Check(Command(2000, 5), true);
  EXPECT_EQ(d.reason, "command_stale_sample");
}

TEST(CommandGate, LockstepTakesTheFirstAnswerOnly) {
  CommandGate gate = TrustingGate(true, 5000);
  EXPECT_FALSE(gate.answered());

  CommandGate::Decision d = gate.Check(Command(4000, 1), true);
  EXPECT_EQ(d.action, Action::kReject);
  EXPECT_EQ(d.reason, "stale_sample_utime");
  EXPECT_EQ(d.detail, "4000 < awaited 5000");
  EXPECT_TRUE(d.timed);
  d = gate.Check(Command(6000, 2), true);
  EXPECT_EQ(d.reason, "command_future_sample");
  EXPECT_FALSE(gate.answered());

  d = gate.Check(Command(5000, 3), true);
  EXPECT_EQ(d.action, Action::kAnswer);
  EXPECT_TRUE(gate.answered());
  EXPECT_EQ(gate.answer().force_n, kForce);

  d = gate.Check(Command(5000, 4, 2 * kForce), true);
  EXPECT_EQ(d.action, Action::kReject);
  EXPECT_EQ(d.reason, "duplicate_answer");
  EXPECT_EQ(d.detail, "sample_utime 5000");
  EXPECT_EQ(gate.answer().force_n, kForce);
  // Lockstep answers are not real-time applications.
  EXPECT_EQ(gate.last_applied_sample_utime(), -1);

  gate.OnSamplePublished(6000);  // the next tick awaits a new answer
  EXPECT_FALSE(gate.answered());
}

// A command the trust rules reject is never the answer: the awaited sample
// stays unanswered, and the real answer that follows still counts.
TEST(CommandGate, LockstepARejectedCommandIsNotTheAnswer) {
  CommandGate gate = TrustingGate(true, 7000);
  ForceCommand forged = Command(7000, 10, Vector6d::Constant(1e300));
  forged.session_id = kSession + 1;  // another stack, a replayed log
  EXPECT_EQ(gate.Check(forged, true).reason, "command_wrong_session");
  EXPECT_EQ(gate.Check(Command(7000, 11, Vector6d::Constant(1e300)), false).reason,
            "command_unauthentic");
  EXPECT_FALSE(gate.answered());
  ASSERT_EQ(gate.Check(Command(7000, 12), true).action, Action::kAnswer);
  EXPECT_EQ(gate.answer().force_n, kForce);
  EXPECT_EQ(gate.answer().seq, 12);
  // A replay of that very answer (same seq) is not a second one either.
  EXPECT_EQ(gate.Check(Command(7000, 12), true).reason, "command_seq_not_increasing");
}

TEST(LoopLatencyTracker, TimesTheFirstCommandOfEachNewerSample) {
  const Clock::time_point t0{};
  LoopLatencyTracker tracker(100, 1000);
  tracker.OnPublished(0, 100, t0);
  tracker.OnPublished(1, 1100, t0 + milliseconds(1));
  EXPECT_EQ(tracker.OnCommand(100, 1, t0 + microseconds(700)), 700);
  EXPECT_EQ(tracker.OnCommand(100, 1, t0 + microseconds(900)), std::nullopt);  // repeat
  EXPECT_EQ(tracker.OnCommand(1100, 1, t0 + microseconds(1250)), 250);
  EXPECT_EQ(tracker.OnCommand(100, 1, t0 + microseconds(1300)), std::nullopt);  // older
}

TEST(LoopLatencyTracker, IgnoresUnknownUnpublishedAndForgottenSamples) {
  const Clock::time_point t0{};
  LoopLatencyTracker tracker(0, 1000);
  tracker.OnPublished(0, 0, t0);
  EXPECT_EQ(tracker.OnCommand(-5, 0, t0), std::nullopt);    // before tick 0
  EXPECT_EQ(tracker.OnCommand(500, 0, t0), std::nullopt);   // not on the tick grid
  EXPECT_EQ(tracker.OnCommand(1000, 0, t0), std::nullopt);  // tick 1 not yet reached
  for (int64_t k = 1; k <= LoopLatencyTracker::kRing; ++k) {
    tracker.OnPublished(k, k * 1000, t0 + milliseconds(k));
  }
  // Tick 0's slot now holds tick kRing: a command for tick 0 is too old.
  EXPECT_EQ(tracker.OnCommand(0, LoopLatencyTracker::kRing, t0), std::nullopt);
  EXPECT_EQ(tracker.published_at(3), t0 + milliseconds(3));
}

TEST(TickAccounting, CountsOverrunsOnlyBeyondOnePeriod) {
  const Clock::time_point t0{};
  LoopLatencyTracker published(0, 1000);
  TickAccounting accounting(0, 1000);
  TickAccounting::Outcome o = accounting.OnTickStart(0, t0, t0 + microseconds(1000), -1, published);
  EXPECT_EQ(o.late_us, 1000);
  EXPECT_FALSE(o.overrun);
  o = accounting.OnTickStart(0, t0, t0 + microseconds(1001), -1, published);
  EXPECT_TRUE(o.overrun);
  EXPECT_TRUE(o.log_overrun);
  EXPECT_EQ(o.missed, TickAccounting::Missed::kNone);  // tick 0 has no previous sample
  EXPECT_EQ(accounting.counters().overrun_ticks, 1);
  EXPECT_EQ(accounting.counters().missed_ticks, 0);
}

TEST(TickAccounting, LogsTheFirstOverrunsThenOneInAHundred) {
  const Clock::time_point t0{};
  LoopLatencyTracker published(0, 1000);
  TickAccounting accounting(0, 1000);
  int logged = 0;
  for (int i = 0; i < 200; ++i) {
    logged += accounting.OnTickStart(0, t0, t0 + milliseconds(5), -1, published).log_overrun;
  }
  EXPECT_EQ(accounting.counters().overrun_ticks, 200);
  EXPECT_EQ(logged, 20 + 2);  // 1..20, 100, 200
}

TEST(TickAccounting, AttributesAMissedTickToWhoeverWasLate) {
  const Clock::time_point t0{};
  LoopLatencyTracker published(0, 1000);
  TickAccounting accounting(0, 1000);
  // Tick 1's sample went out on time: the stack had the whole period.
  published.OnPublished(1, 1000, t0 + milliseconds(1));
  TickAccounting::Outcome o =
      accounting.OnTickStart(2, t0 + milliseconds(2), t0 + milliseconds(2), 0, published);
  EXPECT_EQ(o.missed, TickAccounting::Missed::kStackLate);
  // Tick 2's sample went out 0.7 periods late: the stack had 0.3 of one.
  published.OnPublished(2, 2000, t0 + microseconds(2700));
  o = accounting.OnTickStart(3, t0 + milliseconds(3), t0 + milliseconds(3), 1000, published);
  EXPECT_EQ(o.missed, TickAccounting::Missed::kPlantLate);
  // Answered in time: nothing missed.
  published.OnPublished(3, 3000, t0 + milliseconds(3));
  o = accounting.OnTickStart(4, t0 + milliseconds(4), t0 + milliseconds(4), 3000, published);
  EXPECT_EQ(o.missed, TickAccounting::Missed::kNone);

  const TickCounters& c = accounting.counters();
  EXPECT_EQ(c.missed_ticks, 2);
  EXPECT_EQ(c.missed_stack_late, 1);
  EXPECT_EQ(c.missed_plant_late, 1);
  EXPECT_EQ(c.overrun_ticks, 0);
}

TEST(LockstepPacing, RepublishesTickZeroAtTheStartupPeriodThenTimesOut) {
  const Clock::time_point t0{};
  LockstepPacing pacing(1.0, 0.25);
  pacing.StartWaiting(0, t0);
  LockstepPacing::Step s = pacing.Poll(t0 + milliseconds(100));
  EXPECT_FALSE(s.timed_out);
  EXPECT_FALSE(s.resend);
  EXPECT_EQ(s.wait_ms, LockstepPacing::kMaxWaitMs);
  s = pacing.Poll(t0 + milliseconds(250));
  EXPECT_TRUE(s.resend);
  s = pacing.Poll(t0 + milliseconds(300));
  EXPECT_FALSE(s.resend);  // counted from the resend, not from the start
  s = pacing.Poll(t0 + milliseconds(500));
  EXPECT_TRUE(s.resend);
  s = pacing.Poll(t0 + milliseconds(990));
  EXPECT_EQ(s.wait_ms, 10);  // never waits past the timeout
  EXPECT_TRUE(pacing.Poll(t0 + milliseconds(1000)).timed_out);
}

TEST(LockstepPacing, TickZeroIsNotResentWhenStartupRepublishIsOff) {
  const Clock::time_point t0{};
  LockstepPacing pacing(10.0, 0.0);
  pacing.StartWaiting(0, t0);
  EXPECT_FALSE(pacing.Poll(t0 + milliseconds(5000)).resend);
  // Later ticks are resent when the loop stalls, whatever the start-up setting.
  pacing.StartWaiting(1, t0 + milliseconds(6000));
  EXPECT_FALSE(pacing.Poll(t0 + milliseconds(6199)).resend);
  EXPECT_TRUE(pacing.Poll(t0 + milliseconds(6200)).resend);
}

TEST(RealTimePacing, TicksOnTheGridAndWaitsInBoundedSlices) {
  const Clock::time_point t0{};
  const RealTimePacing pacing(1000, t0);
  EXPECT_EQ(pacing.Deadline(0), t0);
  EXPECT_EQ(pacing.Deadline(7), t0 + milliseconds(7));
  EXPECT_EQ(RealTimePacing::WaitUs(t0 + milliseconds(7), t0 + milliseconds(7)), 0);  // due
  EXPECT_EQ(RealTimePacing::WaitUs(t0 + milliseconds(7), t0 + milliseconds(8)), 0);  // late
  EXPECT_EQ(RealTimePacing::WaitUs(t0 + milliseconds(7), t0 + microseconds(6600)), 401);
  EXPECT_EQ(RealTimePacing::WaitUs(t0 + std::chrono::seconds(2), t0), RealTimePacing::kMaxWaitUs);
}

}  // namespace
}  // namespace stewart
