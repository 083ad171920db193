// The real `estimator` process on a private LCM URL: sensor messages in,
// state estimates out with the sensor sample's utime; bad samples are
// counted in its health; the perfect-state pass-through only on request.
#include <gtest/gtest.h>
#include <signal.h>

#include <chrono>
#include <cmath>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "scenario_truth.h"
#include "stewart/config/config_loader.h"
#include "stewart/force_command_t.hpp"
#include "stewart/health_t.hpp"
#include "stewart/node/lcm_handle.h"
#include "stewart/sensor_t.hpp"
#include "stewart/state_t.hpp"
#include "stewart/supervisor_state_t.hpp"
#include "stewart/test_support/child_process.h"
#include "stewart/test_support/lcm_messages.h"

namespace stewart::test {
namespace {

constexpr int kPortEstimate = 7720;  // this file's private LCM ports
constexpr int kPortPerfect = 7721;

class Sink {
 public:
  void OnState(const lcm::ReceiveBuffer*, const std::string&, const state_t* msg) {
    states.push_back(*msg);
  }
  void OnHealth(const lcm::ReceiveBuffer*, const std::string&, const health_t* msg) {
    if (msg->name == "estimator") health.push_back(*msg);
  }
  std::vector<state_t> states;
  std::vector<health_t> health;
};

sensor_t ToMessage(const SensorSample& s, int64_t seq) {
  sensor_t m{};
  m.utime = s.utime;
  m.seq = seq;
  m.sample_utime = s.utime;
  for (int i = 0; i < 6; ++i) m.leg_length_m[i] = s.leg_length_m(i);
  for (int i = 0; i < 3; ++i) {
    m.gyro_radps[i] = s.gyro_radps(i);
    m.accel_mps2[i] = s.accel_mps2(i);
  }
  return m;
}

int64_t Counter(const health_t& h, const std::string& name) {
  for (int i = 0; i < h.num_counters; ++i) {
    if (h.counter_names[static_cast<size_t>(i)] == name)
      return h.counter_values[static_cast<size_t>(i)];
  }
  return 0;
}

/// The estimator process on a private LCM URL; the test publishes its inputs
/// on `lcm` and finds its estimates and heartbeats in `sink`.
class EstimatorProcess : public ::testing::Test {
 protected:
  /// Starts it with `flags` and waits for its first heartbeat (the process
  /// is up and subscribed).
  void Start(int port, const std::vector<std::string>& flags) {
    const std::string url = PrivateLcmUrl(port);
    lcm = MakeLcm(url);
    lcm->subscribe(ch.state_estimate, &Sink::OnState, &sink)->setQueueCapacity(2000);
    lcm->subscribe(ch.health, &Sink::OnHealth, &sink)->setQueueCapacity(100);
    std::vector<std::string> argv = {ESTIMATOR_BINARY, "--config", DefaultConfigPath(),
                                     "--lcm-url",      url,        "--log-level",
                                     "error"};
    argv.insert(argv.end(), flags.begin(), flags.end());
    proc.emplace(argv);
    ASSERT_TRUE(proc->started());
    ASSERT_TRUE(HandleUntil(
        lcm.get(), [&] { return !sink.health.empty(); }, 10.0));
  }

  const StackConfig config = LoadStackConfig(DefaultConfigPath());
  const ChannelNames& ch = config.lcm.channels;
  std::unique_ptr<lcm::LCM> lcm;
  Sink sink;
  std::optional<ChildProcess> proc;
};

TEST_F(EstimatorProcess, EstimatesCarryTheSensorSampleUtime) {
  ASSERT_NO_FATAL_FAILURE(Start(kPortEstimate, {}));

  ScenarioTruth truth(config, 11);
  constexpr int kSamples = 600;
  constexpr int kNanSample = 300;
  std::map<int64_t, TruthState> published;
  TruthSample previous;
  int64_t seq = 0;
  // The safety session the actuators follow, announced every 50 samples;
  // every 25th sample a forger publishes 50 N per leg under another session
  // (the plant drops those: the estimate must not believe them either).
  constexpr int64_t kSession = 4242;
  int forgeries = 0;
  for (int k = 0; k < kSamples; ++k) {
    const TruthSample t = truth.Next();
    if (k > 0) {
      force_command_t cmd{};
      cmd.utime = previous.utime;
      cmd.seq = k - 1;
      cmd.sample_utime = previous.utime;
      cmd.session_id = kSession;
      for (int i = 0; i < 6; ++i) cmd.force_n[i] = previous.force_n(i);
      if (k % 25 == 0) {
        force_command_t forged = cmd;
        forged.session_id = kSession + 1;
        forged.seq = 1'000'000 + k;
        for (int i = 0; i < 6; ++i) forged.force_n[i] = 50.0;
        lcm->publish(ch.command_safe, &forged);
        ++forgeries;
      }
      lcm->publish(ch.command_safe, &cmd);
    }
    sensor_t msg = ToMessage(t.sensors, seq++);
    if (k == kNanSample) msg.leg_length_m[1] = NAN;
    lcm->publish(ch.sensors, &msg);
    if (k % 50 == 0) {
      supervisor_state_t announcement{};
      announcement.utime = t.utime;
      announcement.seq = k / 50 + 1;
      announcement.session_id = kSession;
      lcm->publish(ch.supervisor, &announcement);
    }
    published[t.utime] = t.state;
    if (k == kNanSample) {
      lcm->publish(ch.sensors, &msg);  // a duplicate: rejected, no estimate
    }
    previous = t;
    lcm->handleTimeout(0);
    std::this_thread::sleep_for(std::chrono::microseconds(300));
  }
  ASSERT_TRUE(HandleUntil(
      lcm.get(), [&] { return sink.states.size() >= kSamples; }, 10.0))
      << "received " << sink.states.size();
  ASSERT_EQ(sink.states.size(), static_cast<size_t>(kSamples));
  for (size_t i = 0; i < sink.states.size(); ++i) {
    const state_t& s = sink.states[i];
    ASSERT_EQ(s.utime, s.sample_utime);
    ASSERT_EQ(s.seq, static_cast<int64_t>(i));
    ASSERT_EQ(published.count(s.sample_utime), 1u) << "unknown sample utime " << s.sample_utime;
    for (int j = 0; j < 6; ++j) ASSERT_TRUE(std::isfinite(s.q[j]) && std::isfinite(s.qd[j]));
    if (i > 0) {
      ASSERT_GT(s.sample_utime, sink.states[i - 1].sample_utime);
    }
  }
  const state_t& last = sink.states.back();
  EXPECT_EQ(last.status, +state_t::STATUS_VALID);
  const TruthState& truth_last = published[last.sample_utime];
  for (int j = 0; j < 3; ++j) {
    EXPECT_NEAR(last.q[j], truth_last.q(j), 2e-4);
    EXPECT_GT(last.q_std[j], 0.0);
    EXPECT_LT(last.q_std[j], 2e-4);
  }
  ASSERT_TRUE(HandleUntil(
      lcm.get(), [&] { return sink.health.back().messages_in >= 2 * kSamples + forgeries; }, 5.0));
  const health_t& h = sink.health.back();
  std::string counters;
  for (int i = 0; i < h.num_counters; ++i) {
    counters += h.counter_names[static_cast<size_t>(i)] + "=" +
                std::to_string(h.counter_values[static_cast<size_t>(i)]) + " ";
  }
  // Health: the NaN legs, the duplicate and the forgeries are counted
  // rejections; every command of the announced session was believed.
  EXPECT_EQ(h.rejected_inputs, 2 + forgeries) << counters;
  EXPECT_EQ(Counter(h, "rejected_legs_non_finite"), 1);
  EXPECT_EQ(Counter(h, "rejected_non_increasing_time"), 1);
  EXPECT_EQ(Counter(h, "rejected_command_wrong_session"), forgeries) << counters;
  EXPECT_EQ(h.messages_out, kSamples);
  EXPECT_EQ(proc->Stop(SIGTERM), 0);
}

TEST_F(EstimatorProcess, PerfectStateOnlyOnRequest) {
  ASSERT_NO_FATAL_FAILURE(Start(kPortPerfect, {"--perfect-state"}));
  state_t truth{};
  truth.utime = 5000;
  truth.seq = 9;
  truth.sample_utime = 5000;
  truth.q[2] = 0.4;
  truth.status = state_t::STATUS_GROUND_TRUTH;
  lcm->publish(ch.state_truth, &truth);
  ASSERT_TRUE(HandleUntil(
      lcm.get(), [&] { return !sink.states.empty(); }, 5.0));
  EXPECT_EQ(sink.states[0].sample_utime, 5000);
  EXPECT_DOUBLE_EQ(sink.states[0].q[2], 0.4);
  EXPECT_EQ(sink.states[0].status, state_t::STATUS_VALID | state_t::STATUS_PERFECT_STATE);
  EXPECT_EQ(proc->Stop(SIGTERM), 0);
}

}  // namespace
}  // namespace stewart::test
