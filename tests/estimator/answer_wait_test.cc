// A sample whose source applied the answer to the previous sample
// (sensor_t::STATUS_ANSWER_APPLIED, lockstep plant_sim) waits for that
// answer: multicast keeps the order of one sender only, so the plant's next
// sample can reach the estimator before the safety process's command. Before,
// the EKF then predicted with the command before it, and two lockstep runs
// of one seed differed from the first overtaken sample on.
#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <vector>

#include "scenario_truth.h"
#include "stewart/config/default_config.h"
#include "stewart/estimator/estimator_process.h"
#include "stewart/test_support/test_clock.h"

namespace stewart {
namespace {

using ::stewart::test::kWallUs;

constexpr int kSamples = 600;

struct Input {
  SensorSample sample;
  ForceCommand answer;  ///< the command answering `sample`
};

/// The paper scenario's samples, each flagged as applying the answer to
/// the one before (as a lockstep plant), with a varying answer.
std::vector<Input> Inputs() {
  const StackConfig& c = DefaultStackConfig();
  test::ScenarioTruth truth(c, 5);
  std::vector<Input> inputs;
  for (int k = 0; k < kSamples; ++k) {
    const test::TruthSample t = truth.Next();
    Input in;
    in.sample = t.sensors;
    in.sample.seq = k;
    in.sample.previous_answer_applied = k > 0;
    in.answer.utime = in.answer.sample_utime = t.utime;
    in.answer.force_n = t.force_n;
    inputs.push_back(in);
  }
  return inputs;
}

EstimatorProcess MakeProcess(HealthCounters* counters) {
  const StackConfig& c = DefaultStackConfig();
  return EstimatorProcess(c.platform, c.actuators, c.sensors, c.estimator, c.home_pose, counters,
                          c.lcm.time_plausibility);
}

struct WaitRun {
  std::vector<StateSample> estimates;
  HealthCounters counters{"estimator"};
};

/// Feeds `inputs`; samples listed in `overtaken` arrive before the answer
/// to the sample before them. Wall time: sample utime + kWallUs.
void Feed(const std::vector<Input>& inputs, const std::vector<int>& overtaken, WaitRun* run) {
  EstimatorProcess process = MakeProcess(&run->counters);
  const auto is_overtaken = [&](int k) {
    return std::find(overtaken.begin(), overtaken.end(), k) != overtaken.end();
  };
  for (int k = 0; k < kSamples; ++k) {
    const Input& in = inputs[static_cast<size_t>(k)];
    const int64_t wall = kWallUs + in.sample.utime;
    StateSample out;
    if (is_overtaken(k)) {
      // The sample first, then the answer to the sample before it.
      EXPECT_FALSE(process.OnSensor(in.sample, &out, wall)) << "sample " << k << " did not wait";
      EXPECT_TRUE(process.waiting());
      EXPECT_TRUE(process.OnCommand(inputs[static_cast<size_t>(k - 1)].answer, &out, wall + 20))
          << "its answer did not release sample " << k;
      run->estimates.push_back(out);
    } else if (process.OnSensor(in.sample, &out, wall)) {
      run->estimates.push_back(out);
    }
    // The answer to this sample, unless the next sample overtakes it.
    if (!is_overtaken(k + 1)) {
      EXPECT_FALSE(process.OnCommand(in.answer, &out, wall + 500));
    }
  }
}

class AnswerWait : public ::testing::Test {
 protected:
  AnswerWait() : inputs_(Inputs()), process_(MakeProcess(&counters_)) {}

  /// Sample 0 estimated; sample 1, flagged, arrives 1 ms later without the
  /// answer to sample 0 and waits.
  void SampleOneWaits() {
    ASSERT_TRUE(process_.OnSensor(inputs_[0].sample, &out_, kWallUs));
    EXPECT_FALSE(process_.OnSensor(inputs_[1].sample, &out_, kWallUs + 1000));
    ASSERT_TRUE(process_.waiting());
  }

  std::vector<Input> inputs_;
  HealthCounters counters_{"estimator"};
  EstimatorProcess process_;
  StateSample out_;
};

TEST_F(AnswerWait, AnOvertakenSampleGivesTheEstimateOfTheCausalOrder) {
  WaitRun in_order;
  Feed(inputs_, {}, &in_order);
  WaitRun overtaken;
  Feed(inputs_, {3, 150, 151, 152, 300, 420, 599}, &overtaken);
  ASSERT_EQ(in_order.estimates.size(), overtaken.estimates.size());
  for (size_t i = 0; i < in_order.estimates.size(); ++i) {
    const StateSample& a = in_order.estimates[i];
    const StateSample& b = overtaken.estimates[i];
    ASSERT_EQ(a.utime, b.utime);
    ASSERT_EQ(a.q, b.q) << "estimate " << i;
    ASSERT_EQ(a.qd, b.qd) << "estimate " << i;
    ASSERT_EQ(a.q_std, b.q_std) << "estimate " << i;
  }
  EXPECT_EQ(overtaken.counters.counter("samples_waited_for_answer"), 7);
  EXPECT_EQ(overtaken.counters.counter("answer_not_heard"), 0);
  EXPECT_EQ(in_order.counters.counter("samples_waited_for_answer"), 0);
}

TEST_F(AnswerWait, WithoutTheFlagASampleNeverWaits) {
  ASSERT_TRUE(process_.OnSensor(inputs_[0].sample, &out_, kWallUs));
  // The answer to sample 0 never comes: sample 1, not flagged, is estimated
  // at once (a real-time source applies whatever command it holds).
  SensorSample one = inputs_[1].sample;
  one.previous_answer_applied = false;
  EXPECT_TRUE(process_.OnSensor(one, &out_, kWallUs + 1000));
  EXPECT_FALSE(process_.waiting());
}

TEST_F(AnswerWait, AnAnswerThatNeverComesCostsAtMostTheWaitAndIsCounted) {
  SampleOneWaits();  // the answer to sample 0 is lost to this process alone
  const int64_t received = kWallUs + 1000;
  const auto wait_us = static_cast<int64_t>(EstimatorProcess::kAnswerWait_s * 1e6);
  EXPECT_FALSE(process_.FlushWaiting(received + wait_us - 1, &out_)) << "flushed before the wait";
  EXPECT_TRUE(process_.waiting());
  // A resend of the waiting sample (lockstep) does not end the wait either.
  EXPECT_FALSE(process_.OnSensor(inputs_[1].sample, &out_, received + 100));
  ASSERT_TRUE(process_.FlushWaiting(received + wait_us, &out_));
  EXPECT_EQ(out_.utime, inputs_[1].sample.utime);
  EXPECT_FALSE(process_.waiting());
  EXPECT_EQ(counters_.counter("answer_not_heard"), 1);
}

TEST_F(AnswerWait, ANewerSampleEndsTheWaitAndIsTheOneEstimated) {
  SampleOneWaits();
  // Sample 2 without the flag: the source moved on without the answer.
  SensorSample next = inputs_[2].sample;
  next.previous_answer_applied = false;
  ASSERT_TRUE(process_.OnSensor(next, &out_, kWallUs + 2000));
  EXPECT_EQ(out_.utime, next.utime);
  EXPECT_FALSE(process_.waiting());
  EXPECT_EQ(counters_.counter("answer_not_heard"), 1);
}

TEST_F(AnswerWait, ARejectedAnswerStillEndsTheWait) {
  SampleOneWaits();
  ForceCommand poisoned = inputs_[0].answer;
  poisoned.force_n(2) = std::numeric_limits<double>::quiet_NaN();
  // The answer came (and was refused): the sample waits no longer.
  ASSERT_TRUE(process_.OnCommand(poisoned, &out_, kWallUs + 1100));
  EXPECT_EQ(out_.utime, inputs_[1].sample.utime);
  EXPECT_TRUE(out_.q.allFinite());
  EXPECT_EQ(counters_.counter("rejected_command_non_finite"), 1);
}

}  // namespace
}  // namespace stewart
