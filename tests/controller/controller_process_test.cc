// The real controller process over LCM on a private URL (ports 7780-7789).
#include <gtest/gtest.h>
#include <signal.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "stewart/config/default_config.h"
#include "stewart/force_command_t.hpp"
#include "stewart/health_t.hpp"
#include "stewart/node/lcm_handle.h"
#include "stewart/setpoint_t.hpp"
#include "stewart/state_t.hpp"
#include "stewart/test_support/child_process.h"

namespace stewart {
namespace {

using Clock = std::chrono::steady_clock;

struct Inbox {
  std::vector<force_command_t> commands;
  std::vector<setpoint_t> setpoints;
  std::vector<health_t> health;
  void OnCommand(const lcm::ReceiveBuffer*, const std::string&, const force_command_t* m) {
    commands.push_back(*m);
  }
  void OnSetpoint(const lcm::ReceiveBuffer*, const std::string&, const setpoint_t* m) {
    setpoints.push_back(*m);
  }
  void OnHealth(const lcm::ReceiveBuffer*, const std::string&, const health_t* m) {
    if (m->name == "controller") health.push_back(*m);
  }
};

state_t State(int64_t utime, const Vector6d& q) {
  state_t s{};
  s.utime = utime;
  s.seq = utime;
  s.sample_utime = utime;
  for (int i = 0; i < 6; ++i) s.q[i] = q(i);
  s.status = state_t::STATUS_VALID;
  return s;
}

class ControllerProcess : public ::testing::Test {
 protected:
  void Connect(int port) {
    url_ = PrivateLcmUrl(port);
    lcm_ = MakeLcm(url_);
    const auto& ch = DefaultStackConfig().lcm.channels;
    lcm_->subscribe(ch.command_nominal, &Inbox::OnCommand, &inbox_)->setQueueCapacity(10000);
    lcm_->subscribe(ch.setpoint, &Inbox::OnSetpoint, &inbox_)->setQueueCapacity(10000);
    lcm_->subscribe(ch.health, &Inbox::OnHealth, &inbox_)->setQueueCapacity(1000);
  }
  void Drain(int ms) {
    const auto end = Clock::now() + std::chrono::milliseconds(ms);
    while (Clock::now() < end) lcm_->handleTimeout(5);
  }
  // Publishes `state` until a command for it arrives (the process may still
  // be starting up). Returns that command's index, or -1.
  int PublishUntilAnswered(state_t state, int timeout_ms = 5000) {
    const auto end = Clock::now() + std::chrono::milliseconds(timeout_ms);
    while (Clock::now() < end) {
      lcm_->publish(DefaultStackConfig().lcm.channels.state_estimate, &state);
      Drain(20);
      for (std::size_t i = 0; i < inbox_.commands.size(); ++i) {
        if (inbox_.commands[i].sample_utime == state.sample_utime) return static_cast<int>(i);
      }
      state.utime += 1;  // a repeated utime would be rejected as not increasing
      state.sample_utime += 1;
    }
    return -1;
  }

  std::string url_;
  std::unique_ptr<lcm::LCM> lcm_;
  Inbox inbox_;
};

TEST_F(ControllerProcess, AnswersStatesWithTheirSampleUtime) {
  Connect(7780);
  test::ChildProcess p({CONTROLLER_PATH, "--lcm-url", url_});
  ASSERT_TRUE(p.started());
  const int first = PublishUntilAnswered(State(1'000'000, DefaultStackConfig().home_pose));
  ASSERT_GE(first, 0) << "no force_command_t from the controller";

  const int64_t t = inbox_.commands[first].sample_utime + 1000;
  inbox_.commands.clear();
  const int i = PublishUntilAnswered(State(t, DefaultStackConfig().home_pose));
  ASSERT_GE(i, 0);
  const force_command_t& cmd = inbox_.commands[i];
  EXPECT_EQ(cmd.sample_utime, t);
  EXPECT_EQ(cmd.utime, t);
  EXPECT_GT(cmd.seq, 0);
  EXPECT_EQ(cmd.flags, 0);
  // At home, at rest, holding home: every leg pushes up against gravity.
  for (double f : cmd.force_n) {
    EXPECT_TRUE(std::isfinite(f));
    EXPECT_GT(f, 0.0);
  }
  // Live mode: nothing is echoed on the setpoint channel.
  EXPECT_TRUE(inbox_.setpoints.empty());

  // A NaN state is rejected: no command for it, ever.
  state_t bad = State(t + 1000, DefaultStackConfig().home_pose);
  bad.qd[2] = std::nan("");
  lcm_->publish(DefaultStackConfig().lcm.channels.state_estimate, &bad);
  // An outside-workspace setpoint: rejected, flagged on the next command.
  setpoint_t sp{};
  sp.utime = t;
  sp.q_des[2] = 1.5;
  lcm_->publish(DefaultStackConfig().lcm.channels.setpoint, &sp);
  Drain(100);
  const int j = PublishUntilAnswered(State(t + 2000, DefaultStackConfig().home_pose));
  ASSERT_GE(j, 0);
  EXPECT_EQ(inbox_.commands[j].flags & force_command_t::FLAG_SETPOINT_REJECTED,
            force_command_t::FLAG_SETPOINT_REJECTED);
  for (const force_command_t& c : inbox_.commands) {
    EXPECT_NE(c.sample_utime, t + 1000);
    for (double f : c.force_n) EXPECT_TRUE(std::isfinite(f));
  }

  // The health heartbeat counts both rejections.
  inbox_.health.clear();
  p.Signal(SIGTERM);
  EXPECT_EQ(p.Wait(std::chrono::seconds(5)), 0);
  Drain(100);
  ASSERT_FALSE(inbox_.health.empty());
  const health_t& h = inbox_.health.back();
  EXPECT_EQ(static_cast<int>(h.state), static_cast<int>(health_t::STATE_STOPPED));
  EXPECT_GE(h.rejected_inputs, 2);
  int64_t nan_states = 0, outside = 0;
  for (int k = 0; k < h.num_counters; ++k) {
    if (h.counter_names[k] == "rejected_state_non_finite") nan_states = h.counter_values[k];
    if (h.counter_names[k] == "rejected_setpoint_outside_workspace") outside = h.counter_values[k];
  }
  EXPECT_EQ(nan_states, 1);
  EXPECT_EQ(outside, 1);
}

TEST_F(ControllerProcess, FollowsAScenarioEchoesItAndExitsAtTheEnd) {
  Connect(7781);
  const std::string path = ::testing::TempDir() + "/controller_process_test_scenario.yaml";
  std::ofstream(path) << "name: short\nduration_s: 0.5\nsegments:\n"
                         "  - {start_s: 0, type: step, q_des: [0.02, 0, 0.4, 0, 0, 0]}\n"
                         "  - {start_s: 0.25, type: step, q_des: [0, 0.03, 0.41, 0, 0, 0]}\n";
  test::ChildProcess p({CONTROLLER_PATH, "--lcm-url", url_, "--scenario", path, "--exit-at-end"});
  ASSERT_TRUE(p.started());
  const int64_t t0 = 5'000'000;
  const int first = PublishUntilAnswered(State(t0, DefaultStackConfig().home_pose));
  ASSERT_GE(first, 0);
  const int64_t start = inbox_.commands[first].sample_utime;  // scenario t = 0
  for (int64_t dt = 10'000; dt <= 600'000; dt += 10'000) {
    const state_t state = State(start + dt, DefaultStackConfig().home_pose);
    lcm_->publish(DefaultStackConfig().lcm.channels.state_estimate, &state);
    Drain(2);
  }
  EXPECT_EQ(p.Wait(std::chrono::seconds(5)), 0) << "did not exit at the scenario's end";
  Drain(100);
  ASSERT_FALSE(inbox_.setpoints.empty());
  bool saw_first = false, saw_second = false;
  for (const setpoint_t& s : inbox_.setpoints) {
    const double t = 1e-6 * static_cast<double>(s.sample_utime - start);
    EXPECT_EQ(s.utime, s.sample_utime);
    if (t >= 0.0 && t < 0.25) {
      EXPECT_DOUBLE_EQ(s.q_des[0], 0.02);
      saw_first = true;
    } else if (t >= 0.25) {
      EXPECT_DOUBLE_EQ(s.q_des[1], 0.03);
      EXPECT_DOUBLE_EQ(s.q_des[2], 0.41);
      saw_second = true;
    }
  }
  EXPECT_TRUE(saw_first);
  EXPECT_TRUE(saw_second);
  // Every command matches one echoed setpoint, by sample_utime.
  EXPECT_EQ(inbox_.commands.size(), inbox_.setpoints.size());
}

TEST(ControllerCli, PrintsTheScenarioDuration) {
  FILE* out = popen(CONTROLLER_PATH " --scenario paper --print-duration", "r");
  ASSERT_NE(out, nullptr);
  char line[64] = {};
  ASSERT_NE(fgets(line, sizeof line, out), nullptr);
  EXPECT_EQ(pclose(out), 0);
  EXPECT_DOUBLE_EQ(std::stod(line), 40.0);

  FILE* bad = popen(CONTROLLER_PATH " --scenario /nonexistent.yaml --print-duration 2>&1", "r");
  ASSERT_NE(bad, nullptr);
  std::string text;
  while (fgets(line, sizeof line, bad) != nullptr) text += line;
  EXPECT_NE(pclose(bad), 0);
  EXPECT_NE(text.find("/nonexistent.yaml"), std::string::npos) << text;
}

}  // namespace
}  // namespace stewart
