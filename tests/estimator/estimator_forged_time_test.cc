// The estimator process against inputs with far-off times, the attacks
// found on the running stack: a sensor sample 1e12 us ahead restarted the
// EKF at that time and every real sample after it was out of order (no
// estimate to the end, health OK); a safe command at utime ~8e18 us (the
// safety process had answered a forged state with it) was filed as the
// newest command. Now both are rejected and counted before the EKF sees
// them, and every estimate after them is the one of the same run without
// them, bit for bit.
#include <gtest/gtest.h>

#include <optional>
#include <vector>

#include "scenario_truth.h"
#include "stewart/config/default_config.h"
#include "stewart/estimator/estimator_process.h"
#include "stewart/test_support/test_clock.h"

namespace stewart {
namespace {

using ::stewart::test::kWallUs;

constexpr int64_t kForgedUtime = 8'000'000'000'000'000'000;

struct ProcessRun {
  std::vector<StateSample> estimates;
  HealthCounters counters{"estimator"};
};

/// `n` samples of the paper scenario, each followed by the command applied
/// after it; `forge` adds the attacks (a sample 1e12 us ahead before sample
/// 300, a command at 8e18 us after sample 400).
void RunProcess(int n, bool live, bool forge, ProcessRun* run) {
  const StackConfig& c = DefaultStackConfig();
  test::ScenarioTruth truth(c, 7);
  EstimatorProcess process(c.platform, c.actuators, c.sensors, c.estimator, c.home_pose,
                           &run->counters, c.lcm.time_plausibility);
  for (int k = 0; k < n; ++k) {
    const test::TruthSample sample = truth.Next();
    const std::optional<int64_t> wall =
        live ? std::optional<int64_t>(kWallUs + sample.utime) : std::nullopt;
    StateSample out;
    if (forge && k == 300) {
      SensorSample ahead = sample.sensors;
      ahead.utime += 1'000'000'000'000;
      EXPECT_FALSE(process.OnSensor(ahead, &out, wall));
    }
    if (process.OnSensor(sample.sensors, &out, wall)) run->estimates.push_back(out);
    ForceCommand command;
    command.utime = command.sample_utime = sample.utime;
    command.force_n = sample.force_n;
    EXPECT_FALSE(process.OnCommand(command, &out, wall));
    if (forge && k == 400) {
      ForceCommand forged = command;
      forged.utime = forged.sample_utime = kForgedUtime;
      forged.force_n = Vector6d::Constant(40.0);
      EXPECT_FALSE(process.OnCommand(forged, &out, wall));
    }
  }
}

class EstimatorForgedTime : public ::testing::TestWithParam<bool> {};  // live or replay

TEST_P(EstimatorForgedTime, FarOffSampleAndCommandAreRejectedAndTheEstimatesUnchanged) {
  constexpr int kSamples = 1000;
  ProcessRun clean, attacked;
  RunProcess(kSamples, GetParam(), false, &clean);
  RunProcess(kSamples, GetParam(), true, &attacked);
  EXPECT_EQ(attacked.counters.counter("rejected_sensor_time_implausible"), 1);
  EXPECT_EQ(attacked.counters.counter("rejected_command_time_implausible"), 1);
  EXPECT_EQ(attacked.counters.counter("rejected_non_increasing_time"),
            0);  // no real sample out of order
  EXPECT_EQ(attacked.counters.rejected_inputs(), clean.counters.rejected_inputs() + 2);
  EXPECT_NE(attacked.counters.state(), health_state::kFault);
  ASSERT_EQ(clean.estimates.size(), static_cast<size_t>(kSamples));
  ASSERT_EQ(attacked.estimates.size(), clean.estimates.size());
  for (size_t i = 0; i < clean.estimates.size(); ++i) {
    const StateSample& a = attacked.estimates[i];
    const StateSample& b = clean.estimates[i];
    ASSERT_EQ(a.utime, b.utime) << i;
    EXPECT_EQ(a.q, b.q) << i;
    EXPECT_EQ(a.qd, b.qd) << i;
    EXPECT_EQ(a.disturbance, b.disturbance) << i;
    EXPECT_EQ(a.status, b.status) << i;
  }
}

INSTANTIATE_TEST_SUITE_P(ReceiveTimes, EstimatorForgedTime, ::testing::Bool(),
                         [](const ::testing::TestParamInfo<bool>& param_info) {
                           return param_info.param ? "live" : "replay";
                         });

// A lockstep resend (common/resend_answer.h): the sample answered last,
// received again, is answered with the same estimate and the EKF is not
// stepped twice; live, a copy within 0.1 s of the answer is only a copy.
void RunWithResend(int n, bool live, int resend_at, ProcessRun* run, int* copies_answered) {
  const StackConfig& c = DefaultStackConfig();
  test::ScenarioTruth truth(c, 7);
  EstimatorProcess process(c.platform, c.actuators, c.sensors, c.estimator, c.home_pose,
                           &run->counters, c.lcm.time_plausibility);
  for (int k = 0; k < n; ++k) {
    test::TruthSample sample = truth.Next();
    sample.sensors.seq = k;
    const std::optional<int64_t> wall =
        live ? std::optional<int64_t>(kWallUs + sample.utime) : std::nullopt;
    StateSample out;
    if (process.OnSensor(sample.sensors, &out, wall)) run->estimates.push_back(out);
    if (k == resend_at) {
      if (live) {
        // A copy right after the answer: a duplicate, not a stall.
        StateSample copy;
        EXPECT_FALSE(process.OnSensor(sample.sensors, &copy, *wall + 1000));
      }
      // plant_sim's resend 0.2 s later, and again.
      for (int i = 1; i <= 2; ++i) {
        StateSample again;
        const std::optional<int64_t> resend_wall =
            live ? std::optional<int64_t>(*wall + 200'000 * i) : std::nullopt;
        if (process.OnSensor(sample.sensors, &again, resend_wall)) {
          ++*copies_answered;
          EXPECT_EQ(again.utime, out.utime);
          EXPECT_EQ(again.seq, out.seq);
          EXPECT_EQ(again.q, out.q);
          EXPECT_EQ(again.qd, out.qd);
          EXPECT_EQ(again.disturbance, out.disturbance);
          EXPECT_EQ(again.q_std, out.q_std);
        }
      }
    }
    ForceCommand command;
    command.utime = command.sample_utime = sample.utime;
    command.force_n = sample.force_n;
    EXPECT_FALSE(process.OnCommand(command, &out, wall));
  }
}

class EstimatorResend : public ::testing::TestWithParam<bool> {};  // live or replay

TEST_P(EstimatorResend, TheSampleAnsweredLastIsAnsweredAgainWithoutASecondUpdate) {
  constexpr int kSamples = 600;
  ProcessRun clean, resent;
  int unused = 0, answered = 0;
  RunWithResend(kSamples, GetParam(), -1, &clean, &unused);
  RunWithResend(kSamples, GetParam(), 300, &resent, &answered);
  EXPECT_EQ(answered, 2);
  EXPECT_EQ(resent.counters.counter("resends_answered"), 2);
  // Live, the copy within 0.1 s was refused as before, as out of order.
  EXPECT_EQ(resent.counters.counter("rejected_non_increasing_time"), GetParam() ? 1 : 0);
  // The estimates after it are those of the run without the resend: the EKF
  // did not step on the copies.
  ASSERT_EQ(resent.estimates.size(), clean.estimates.size());
  for (size_t i = 0; i < clean.estimates.size(); ++i) {
    ASSERT_EQ(resent.estimates[i].utime, clean.estimates[i].utime) << i;
    EXPECT_EQ(resent.estimates[i].seq, clean.estimates[i].seq) << i;
    EXPECT_EQ(resent.estimates[i].q, clean.estimates[i].q) << i;
    EXPECT_EQ(resent.estimates[i].qd, clean.estimates[i].qd) << i;
    EXPECT_EQ(resent.estimates[i].disturbance, clean.estimates[i].disturbance) << i;
  }
}

INSTANTIATE_TEST_SUITE_P(ReceiveTimes, EstimatorResend, ::testing::Bool(),
                         [](const ::testing::TestParamInfo<bool>& param_info) {
                           return param_info.param ? "live" : "replay";
                         });

}  // namespace
}  // namespace stewart
