// The safety process against messages with far-off times, the attacks found
// on the running stack: a valid state estimate at utime ~8e18 us made it
// reject every real state afterwards (and answer the forged one, with its
// time); a nominal command 1e12 us ahead held its controller watchdog off
// for good. Now both are rejected and counted, neither becomes the newest
// time, and every real message after them is answered exactly as in the same
// run without them: the watchdog still fires when the controller stops.
#include <gtest/gtest.h>

#include <functional>
#include <optional>
#include <vector>

#include "safety_test_support.h"
#include "stewart/common/health_counters.h"
#include "stewart/safety/safety_process.h"
#include "stewart/test_support/test_clock.h"

namespace stewart::safety::test {
namespace {

using ::stewart::test::kWallUs;

// Armed at the first filtered step: these tests are about message times.
SupervisorConfig Armed() {
  SupervisorConfig c;
  c.auto_arm = true;
  c.arming_ramp_s = 0.0;
  return c;
}

constexpr int64_t kStartUtime = 1'000'000;
constexpr int64_t kSamplePeriodUs = 1000;
constexpr int64_t kForgedUtime = 8'000'000'000'000'000'000;

struct TimedAnswer {
  int64_t sample_utime;
  Vector6d force_n;
  int32_t flags;
  bool operator==(const TimedAnswer& o) const {
    return sample_utime == o.sample_utime && force_n == o.force_n && flags == o.flags;
  }
};

StateSample StateAt(int64_t utime) {
  StateSample s;
  s.utime = s.sample_utime = utime;
  s.q = DefaultConfig().home_pose;
  s.status = kStateValid;
  return s;
}

ForceCommand NominalFor(int64_t sample_utime) {
  ForceCommand n;
  n.utime = n.sample_utime = sample_utime;
  n.force_n = HoverForce(DefaultConfig().home_pose) + Vector6d::Constant(0.5);
  return n;
}

/// Samples 0..n-1, each state followed by its nominal command until the
/// controller stops at `controller_stops_at`; `inject` runs before sample k's
/// state. With `live`, every message has a receive time (the wall clock
/// advancing with stack time, as in real time); without, none (replay).
struct ProcessRun {
  std::vector<TimedAnswer> answers;
  HealthCounters counters{"safety"};
};
void RunProcess(int n, int controller_stops_at, bool live,
                const std::function<void(int k, SafetyProcess&, std::optional<int64_t>)>& inject,
                ProcessRun* run) {
  const StackConfig& c = DefaultConfig();
  SafetyProcess process(c.platform, c.safety, c.actuators, Armed(), nullptr, &run->counters,
                        c.lcm.time_plausibility);
  SafetyOutput out;
  for (int k = 0; k < n; ++k) {
    const int64_t utime = kStartUtime + k * kSamplePeriodUs;
    const std::optional<int64_t> wall =
        live ? std::optional<int64_t>(kWallUs + k * kSamplePeriodUs) : std::nullopt;
    if (inject) inject(k, process, wall);
    if (process.OnState(StateAt(utime), &out, wall)) {
      run->answers.push_back({out.command.sample_utime, out.command.force_n, out.command.flags});
    }
    if (k < controller_stops_at && process.OnNominal(NominalFor(utime), &out, wall)) {
      run->answers.push_back({out.command.sample_utime, out.command.force_n, out.command.flags});
    }
  }
}

class SafetyForgedTime : public ::testing::TestWithParam<bool> {};  // live or replay

TEST_P(SafetyForgedTime, FarFutureStateIsRejectedAndTheRealStatesAnsweredAsWithoutIt) {
  constexpr int kSamples = 120;
  ProcessRun clean, attacked;
  RunProcess(kSamples, kSamples, GetParam(), nullptr, &clean);
  bool forged_answered = false;
  RunProcess(
      kSamples, kSamples, GetParam(),
      [&](int k, SafetyProcess& p, std::optional<int64_t> wall) {
        if (k != 50) return;
        SafetyOutput out;
        forged_answered = p.OnState(StateAt(kForgedUtime), &out, wall);
      },
      &attacked);
  EXPECT_FALSE(forged_answered) << "a command went out for the forged state";
  EXPECT_EQ(attacked.counters.counter("rejected_state_time_implausible"), 1);
  EXPECT_EQ(attacked.counters.rejected_inputs(), 1);
  EXPECT_EQ(attacked.counters.counter("rejected_state_time_not_increasing"), 0);
  EXPECT_EQ(attacked.counters.state(), health_state::kOk);
  EXPECT_LT(attacked.counters.utime(), kForgedUtime);
  ASSERT_EQ(clean.answers.size(), static_cast<size_t>(kSamples));  // one per sample
  ASSERT_EQ(attacked.answers.size(), clean.answers.size());
  for (size_t i = 0; i < clean.answers.size(); ++i) {
    EXPECT_TRUE(attacked.answers[i] == clean.answers[i]) << "sample " << i;
    EXPECT_FALSE(attacked.answers[i].flags & kCommandFallback) << "sample " << i;
  }
}

TEST_P(SafetyForgedTime, FarFutureNominalDoesNotDisableTheWatchdog) {
  constexpr int kSamples = 120, kControllerStops = 60;
  const int64_t stale_us = static_cast<int64_t>(DefaultConfig().safety.stale_age_s * 1e6);
  ProcessRun clean, attacked;
  RunProcess(kSamples, kControllerStops, GetParam(), nullptr, &clean);
  RunProcess(
      kSamples, kControllerStops, GetParam(),
      [&](int k, SafetyProcess& p, std::optional<int64_t> wall) {
        if (k != 55) return;
        SafetyOutput out;
        const int64_t ahead = kStartUtime + k * kSamplePeriodUs + 1'000'000'000'000;
        EXPECT_FALSE(p.OnNominal(NominalFor(ahead), &out, wall));
      },
      &attacked);
  EXPECT_EQ(attacked.counters.counter("rejected_nominal_time_implausible"), 1);
  ASSERT_EQ(attacked.answers.size(), clean.answers.size());
  for (size_t i = 0; i < clean.answers.size(); ++i) {
    EXPECT_TRUE(attacked.answers[i] == clean.answers[i]) << "answer " << i;
  }
  // The watchdog: stale-input fallbacks from stale_age_s after the last
  // nominal command on, for every later state.
  const int64_t last_nominal = kStartUtime + (kControllerStops - 1) * kSamplePeriodUs;
  int fallbacks = 0;
  for (const TimedAnswer& a : attacked.answers) {
    if (a.sample_utime - last_nominal > stale_us + kSamplePeriodUs) {
      EXPECT_TRUE(a.flags & kCommandStaleInput) << a.sample_utime;
      ++fallbacks;
    }
  }
  EXPECT_GT(fallbacks, 30);
}

TEST_P(SafetyForgedTime, NominalAheadOfEveryStateWithinTheWindowCannotHoldTheWatchdogOff) {
  // 0.5 s ahead is within lcm.time_window_s: not implausible, but it answers
  // no state this process has seen, so it shows no controller alive.
  constexpr int kSamples = 120, kControllerStops = 60;
  ProcessRun clean, attacked;
  RunProcess(kSamples, kControllerStops, GetParam(), nullptr, &clean);
  RunProcess(
      kSamples, kControllerStops, GetParam(),
      [&](int k, SafetyProcess& p, std::optional<int64_t> wall) {
        if (k != 55) return;
        SafetyOutput out;
        EXPECT_FALSE(
            p.OnNominal(NominalFor(kStartUtime + k * kSamplePeriodUs + 500'000), &out, wall));
      },
      &attacked);
  EXPECT_EQ(attacked.counters.counter("rejected_nominal_time_implausible"), 0);
  ASSERT_EQ(attacked.answers.size(), clean.answers.size());
  for (size_t i = 0; i < clean.answers.size(); ++i) {
    EXPECT_TRUE(attacked.answers[i] == clean.answers[i]) << "answer " << i;
  }
  EXPECT_TRUE(attacked.answers.back().flags & kCommandStaleInput);
}

INSTANTIATE_TEST_SUITE_P(ReceiveTimes, SafetyForgedTime, ::testing::Bool(),
                         [](const ::testing::TestParamInfo<bool>& param_info) {
                           return param_info.param ? "live" : "replay";
                         });

TEST(SafetyForgedTime, RejectingEveryStateIsAFaultThatLatchesAndRecovers) {
  // A plant started again in lockstep (stack time from 0) while this process
  // is at 60 s: every state is behind the window. Longer than the stale age:
  // FAULT, latched; plausible states again: OK, still latched.
  const StackConfig& c = DefaultConfig();
  HealthCounters counters("safety");
  SafetyProcess process(c.platform, c.safety, c.actuators, Armed(), nullptr, &counters,
                        c.lcm.time_plausibility);
  SafetyOutput out;
  int64_t wall = kWallUs;
  const auto state_then_nominal = [&](int64_t utime) {
    wall += kSamplePeriodUs;
    const bool answered = process.OnState(StateAt(utime), &out, wall);
    return process.OnNominal(NominalFor(utime), &out, wall) || answered;
  };
  for (int k = 0; k < 10; ++k) ASSERT_TRUE(state_then_nominal(60'000'000 + k * kSamplePeriodUs));
  EXPECT_EQ(counters.state(), health_state::kOk);
  for (int k = 0; k < 40; ++k) EXPECT_FALSE(state_then_nominal(k * kSamplePeriodUs));
  EXPECT_EQ(counters.state(), health_state::kFault);
  EXPECT_TRUE(counters.fault_latched());
  EXPECT_EQ(counters.counter("rejected_state_time_implausible"), 40);
  EXPECT_EQ(counters.utime(), 60'000'000 + 9 * kSamplePeriodUs);  // the newest time did not move
  EXPECT_TRUE(state_then_nominal(60'000'000 + 10 * kSamplePeriodUs));
  EXPECT_EQ(counters.state(), health_state::kOk);
  EXPECT_TRUE(counters.fault_latched());
}

}  // namespace
}  // namespace stewart::safety::test
