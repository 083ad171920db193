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

}  // namespace
}  // namespace stewart
