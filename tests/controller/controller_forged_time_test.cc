// The controller process against a state estimate with a far-off time (the
// attack found on the running stack: one valid state at utime ~8e18 us made
// it reject every real state afterwards, as out of order). Now it is
// rejected and counted before the control law sees it, and every real state
// after it gets the nominal command it gets in the same run without it: the
// scenario clock did not move.
#include <gtest/gtest.h>

#include <optional>
#include <vector>

#include "stewart/config/default_config.h"
#include "stewart/config/scenario_loader.h"
#include "stewart/controller/controller_process.h"

namespace stewart {
namespace {

constexpr int64_t kStartUtime = 3'000'000;
constexpr int64_t kPeriodUs = 1000;
constexpr int64_t kWall = 1'780'000'000'000'000;
constexpr int64_t kForgedUtime = 8'000'000'000'000'000'000;

StateSample StateAt(int64_t utime, int k) {
  StateSample s;
  s.utime = s.sample_utime = utime;
  s.q = DefaultStackConfig().home_pose;
  s.q(0) += 1e-5 * k;  // moving, so the commands differ from step to step
  s.qd(0) = 0.01;
  s.status = kStateValid;
  return s;
}

struct ProcessRun {
  std::vector<ControllerProcessOutput> outputs;
  HealthCounters counters{"controller"};
  std::optional<ControllerVerdict> forged_verdict;
};

void RunProcess(int n, bool live, std::optional<int> forge_at, ProcessRun* run) {
  const StackConfig& c = DefaultStackConfig();
  ControllerProcess process(c.platform, c.controller, c.home_pose,
                            LoadScenario(ResolveScenarioPath("paper")), &run->counters,
                            c.lcm.time_plausibility);
  for (int k = 0; k < n; ++k) {
    const std::optional<int64_t> wall =
        live ? std::optional<int64_t>(kWall + k * kPeriodUs) : std::nullopt;
    ControllerProcessOutput out;
    if (forge_at && k == *forge_at) {
      StateSample forged = StateAt(kForgedUtime, k);
      run->forged_verdict = process.OnState(forged, &out, wall);
    }
    ASSERT_EQ(process.OnState(StateAt(kStartUtime + k * kPeriodUs, k), &out, wall),
              ControllerVerdict::kPublished)
        << "sample " << k;
    run->outputs.push_back(out);
  }
}

class ControllerForgedTime : public ::testing::TestWithParam<bool> {};  // live or replay

TEST_P(ControllerForgedTime, FarFutureStateIsRejectedAndTheRealStatesGetTheirCommands) {
  constexpr int kSamples = 200;
  ProcessRun clean, attacked;
  RunProcess(kSamples, GetParam(), std::nullopt, &clean);
  RunProcess(kSamples, GetParam(), 100, &attacked);
  ASSERT_TRUE(attacked.forged_verdict.has_value());
  EXPECT_EQ(*attacked.forged_verdict, ControllerVerdict::kTimeImplausible);
  EXPECT_EQ(attacked.counters.counter("rejected_state_time_implausible"), 1);
  EXPECT_EQ(attacked.counters.counter("rejected_state_time_not_increasing"), 0);
  EXPECT_EQ(attacked.counters.rejected_inputs(), 1);
  EXPECT_EQ(attacked.counters.messages_out(), kSamples);
  EXPECT_EQ(attacked.counters.utime(), kStartUtime + (kSamples - 1) * kPeriodUs);
  ASSERT_EQ(attacked.outputs.size(), clean.outputs.size());
  for (size_t i = 0; i < clean.outputs.size(); ++i) {
    const ControllerProcessOutput& a = attacked.outputs[i];
    const ControllerProcessOutput& b = clean.outputs[i];
    EXPECT_EQ(a.command.sample_utime, b.command.sample_utime) << i;
    EXPECT_EQ(a.command.seq, b.command.seq) << i;  // no command went out for the forged state
    EXPECT_EQ(a.command.force_n, b.command.force_n) << i;
    EXPECT_EQ(a.setpoint_echo.setpoint.q_des, b.setpoint_echo.setpoint.q_des) << i;
  }
}

INSTANTIATE_TEST_SUITE_P(ReceiveTimes, ControllerForgedTime, ::testing::Bool(),
                         [](const ::testing::TestParamInfo<bool>& param_info) {
                           return param_info.param ? "live" : "replay";
                         });

TEST(ControllerForgedTime, AReceiveTimeNeverChangesACommand) {
  // The receive time only widens the window after a gap: on a normal stream
  // the live and the replayed process publish the same commands.
  ProcessRun live, replay;
  RunProcess(300, true, std::nullopt, &live);
  RunProcess(300, false, std::nullopt, &replay);
  ASSERT_EQ(live.outputs.size(), replay.outputs.size());
  for (size_t i = 0; i < live.outputs.size(); ++i) {
    EXPECT_EQ(live.outputs[i].command.force_n, replay.outputs[i].command.force_n) << i;
  }
}

TEST(ControllerResend, TheStateAnsweredLastIsAnsweredAgainWithoutASecondStep) {
  // A lockstep resend (common/resend_answer.h): the same command and
  // setpoint echo again, the control law and the scenario not stepped, so
  // the commands after it are those of a run without the resend; live, a
  // copy within 0.1 s of the answer is refused as before.
  for (const bool live : {true, false}) {
    SCOPED_TRACE(live ? "live" : "replay");
    ProcessRun clean;
    RunProcess(300, live, std::nullopt, &clean);
    const StackConfig& c = DefaultStackConfig();
    HealthCounters counters{"controller"};
    ControllerProcess process(c.platform, c.controller, c.home_pose,
                              LoadScenario(ResolveScenarioPath("paper")), &counters,
                              c.lcm.time_plausibility);
    std::vector<ControllerProcessOutput> outputs;
    int answered = 0;
    for (int k = 0; k < 300; ++k) {
      const auto wall = [&](int64_t after_us) {
        return live ? std::optional<int64_t>(kWall + k * kPeriodUs + after_us) : std::nullopt;
      };
      StateSample state = StateAt(kStartUtime + k * kPeriodUs, k);
      state.seq = k;
      ControllerProcessOutput out;
      ASSERT_EQ(process.OnState(state, &out, wall(0)), ControllerVerdict::kPublished);
      outputs.push_back(out);
      if (k != 150) continue;
      ControllerProcessOutput again;
      if (live) {
        EXPECT_EQ(process.OnState(state, &again, wall(1000)), ControllerVerdict::kStepRejected);
      }
      ASSERT_EQ(process.OnState(state, &again, wall(200'000)), ControllerVerdict::kPublished);
      ++answered;
      EXPECT_EQ(again.command.seq, out.command.seq);
      EXPECT_EQ(again.command.force_n, out.command.force_n);
      EXPECT_EQ(again.setpoint_echo.seq, out.setpoint_echo.seq);
      EXPECT_EQ(again.setpoint_echo.setpoint.q_des, out.setpoint_echo.setpoint.q_des);
    }
    EXPECT_EQ(answered, 1);
    EXPECT_EQ(counters.counter("resends_answered"), 1);
    EXPECT_EQ(counters.counter("rejected_state_time_not_increasing"), live ? 1 : 0);
    ASSERT_EQ(outputs.size(), clean.outputs.size());
    for (size_t i = 0; i < outputs.size(); ++i) {
      EXPECT_EQ(outputs[i].command.force_n, clean.outputs[i].command.force_n) << i;
      EXPECT_EQ(outputs[i].command.seq, clean.outputs[i].command.seq) << i;
    }
  }
}

}  // namespace
}  // namespace stewart
