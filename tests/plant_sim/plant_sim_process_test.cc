// The real plant_sim process over LCM (private URLs, ports 7700-7719, ttl=0).
#include <gtest/gtest.h>

#include <chrono>
#include <fstream>
#include <lcm/lcm-cpp.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "plant_test_util.h"
#include "stewart/config/config_loader.h"
#include "stewart/config/truth_loader.h"
#include "stewart/force_command_t.hpp"
#include "stewart/health_t.hpp"
#include "stewart/model/dynamics.h"
#include "stewart/model/kinematics.h"
#include "stewart/node/lcm_handle.h"
#include "stewart/sensor_t.hpp"
#include "stewart/state_t.hpp"
#include "stewart/test_support/child_process.h"
#include "stewart/test_support/fake_safety_session.h"

namespace stewart {
namespace {

using Clock = std::chrono::steady_clock;
using test::Config;

// Records what plant_sim publishes and, if asked, answers every sensor
// sample with a leg-space P controller around the holding force.
class Stack {
 public:
  /// hold_only: answer with the model's holding force alone (no feedback).
  Stack(const std::string& url, bool answer, bool hold_only = false)
      : lcm_(MakeLcm(url)),
        safety_(lcm_.get(), Config().lcm.channels.supervisor, Config().lcm.channels.command_safe),
        answer_(answer),
        hold_only_(hold_only) {
    const auto& ch = Config().lcm.channels;
    lcm_->subscribe(ch.sensors, &Stack::OnSensor, this)->setQueueCapacity(10000);
    lcm_->subscribe(ch.state_truth, &Stack::OnTruth, this)->setQueueCapacity(10000);
    lcm_->subscribe(ch.health, &Stack::OnHealth, this)->setQueueCapacity(100);
    const Vector6d q0 = Config().plant_sim.initial_pose;
    hold_n_ = test::HoldingForce(Config().platform, q0);
    l_target_ = InverseKinematics(Config().platform, q0) + Vector6d::Constant(0.005);
  }
  void Spin(double seconds) {
    const auto end = Clock::now() + std::chrono::duration<double>(seconds);
    while (Clock::now() < end) lcm_->handleTimeout(5);
  }
  void SpinUntilExit(test::ChildProcess* p, double max_seconds) {
    const auto end = Clock::now() + std::chrono::duration<double>(max_seconds);
    while (Clock::now() < end && p->running()) lcm_->handleTimeout(5);
    while (lcm_->handleTimeout(20) > 0) {
    }
  }
  void PublishCommand(int64_t sample_utime, const Vector6d& f) {
    force_command_t cmd{};
    cmd.utime = sample_utime;
    cmd.sample_utime = sample_utime;
    for (int i = 0; i < 6; ++i) cmd.force_n[i] = f(i);
    safety_.Publish(cmd);
  }

  std::vector<sensor_t> sensors;
  std::vector<state_t> truth;
  std::vector<std::vector<uint8_t>> truth_bytes;
  std::vector<health_t> health;
  Vector6d hold_n_, l_target_;

 private:
  void OnSensor(const lcm::ReceiveBuffer*, const std::string&, const sensor_t* s) {
    if (!sensors.empty() && sensors.back().seq == s->seq) return;  // startup resend
    sensors.push_back(*s);
    if (!answer_) return;
    if (hold_only_) {
      PublishCommand(s->utime, hold_n_);
      return;
    }
    Vector6d l;
    for (int i = 0; i < 6; ++i) l(i) = s->leg_length_m[i];
    PublishCommand(s->utime, hold_n_ + 800.0 * (l_target_ - l));
  }
  void OnTruth(const lcm::ReceiveBuffer* rbuf, const std::string&, const state_t* s) {
    truth.push_back(*s);
    const auto* data = static_cast<const uint8_t*>(rbuf->data);
    truth_bytes.emplace_back(data, data + rbuf->data_size);
  }
  void OnHealth(const lcm::ReceiveBuffer*, const std::string&, const health_t* h) {
    if (h->name == "plant_sim") health.push_back(*h);
  }

  std::unique_ptr<lcm::LCM> lcm_;
  test::FakeSafetySession safety_;
  bool answer_;
  bool hold_only_;
};

TEST(PlantSimProcess, RealTimePublishesAndReactsToCommands) {
  const std::string url = PrivateLcmUrl(7700);
  Stack stack(url, false);
  test::ChildProcess sim({PLANT_SIM_BIN, "--lcm-url", url, "--mode", "realtime", "--duration", "3",
                          "--log-level", "warn"});
  ASSERT_TRUE(sim.running());
  stack.Spin(0.5);  // no commands: actuators off, legs locked
  ASSERT_GT(stack.sensors.size(), 100u);
  ASSERT_FALSE(stack.truth.empty());
  EXPECT_TRUE(stack.sensors.back().status & sensor_t::STATUS_ACTUATORS_OFF);
  EXPECT_TRUE(stack.truth.back().status & state_t::STATUS_GROUND_TRUTH);
  const double z_locked = stack.truth.back().q[2];
  EXPECT_NEAR(z_locked, Config().plant_sim.initial_pose(2), 1e-4);
  ASSERT_FALSE(stack.health.empty());
  EXPECT_EQ(stack.health.back().state,
            static_cast<int8_t>(health_t::STATE_DEGRADED));  // says the fallback is on

  // Push up for 0.3 s: holding force + 0.06 N per leg, answered every 2 ms.
  // Against the legs' friction (2 N s/m) they rise at up to 30 mm/s, under
  // plant_sim's guard (guard.leg_speed_cap_mps; a harder push trips it:
  // plant_sim_trust_test).
  const auto end = Clock::now() + std::chrono::milliseconds(300);
  while (Clock::now() < end) {
    stack.PublishCommand(stack.sensors.back().utime, stack.hold_n_ + Vector6d::Constant(0.06));
    stack.Spin(0.002);
  }
  EXPECT_GT(stack.truth.back().q[2], z_locked + 2e-3);
  EXPECT_FALSE(stack.sensors.back().status & sensor_t::STATUS_ACTUATORS_OFF);
  // Commands stop: the timeout locks the legs again and health says so.
  stack.Spin(0.4);
  EXPECT_TRUE(stack.sensors.back().status & sensor_t::STATUS_ACTUATORS_OFF);
  EXPECT_EQ(stack.health.back().state, static_cast<int8_t>(health_t::STATE_DEGRADED));
  const double z_relocked = stack.truth.back().q[2];
  stack.Spin(0.2);
  EXPECT_NEAR(stack.truth.back().q[2], z_relocked, 1e-4);
  // utime runs on the tick grid: 1 kHz -> 1000 us apart, seq by one.
  const auto& s = stack.sensors;
  EXPECT_EQ(s[s.size() - 1].utime - s[s.size() - 2].utime, 1000);
  EXPECT_EQ(s[s.size() - 1].seq - s[s.size() - 2].seq, 1);
}

std::vector<std::vector<uint8_t>> LockstepRun(int port) {
  const std::string url = PrivateLcmUrl(port);
  Stack stack(url, true);
  test::ChildProcess sim({PLANT_SIM_BIN, "--lcm-url", url, "--mode", "lockstep", "--duration",
                          "0.5", "--seed", "11", "--log-level", "warn"});
  EXPECT_TRUE(sim.running());
  stack.SpinUntilExit(&sim, 15.0);
  EXPECT_EQ(sim.Wait(), 0);
  EXPECT_EQ(stack.truth.size(), 501u);  // ticks 0..500 (t = 0 .. 0.5 s)
  if (!stack.truth.empty()) {
    EXPECT_EQ(stack.truth.front().utime, 0);
    EXPECT_GT(stack.truth.back().q[2], Config().plant_sim.initial_pose(2) + 1e-3);  // it moved
  }
  return stack.truth_bytes;
}

TEST(PlantSimProcess, LockstepGivesByteIdenticalGroundTruth) {
  const auto a = LockstepRun(7701);
  const auto b = LockstepRun(7702);
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) ASSERT_EQ(a[i], b[i]) << "tick " << i;
}

// plant_sim --truth: a platform 50 % heavier than the model, held by the
// model's holding force and nothing else, sinks with the acceleration the
// truth's dynamics give (friction off in the truth, so it is the only
// force besides gravity); without the truth it stays put.
double SinkAfter(int port, const std::string& truth_path, double duration_s) {
  const std::string url = PrivateLcmUrl(port);
  Stack stack(url, true, /*hold_only=*/true);
  std::vector<std::string> args = {PLANT_SIM_BIN,
                                   "--lcm-url",
                                   url,
                                   "--mode",
                                   "lockstep",
                                   "--duration",
                                   std::to_string(duration_s),
                                   "--log-level",
                                   "warn"};
  if (!truth_path.empty()) {
    args.push_back("--truth");
    args.push_back(truth_path);
  }
  // The platform falls freely here, at metres per second squared: plant_sim's
  // guard would stop it within a few centimetres per second (as it should);
  // this test measures the physics, so its cap is out of the way.
  const std::string overlay = testing::TempDir() + "/no_speed_guard.yaml";
  std::ofstream(overlay) << "guard: {leg_speed_cap_mps: 100.0}\n";
  args.push_back("--overlay");
  args.push_back(overlay);
  test::ChildProcess sim(args);
  EXPECT_TRUE(sim.running());
  stack.SpinUntilExit(&sim, 15.0);
  EXPECT_EQ(sim.Wait(), 0);
  if (stack.truth.empty()) return NAN;
  return stack.truth.back().q[2] - Config().plant_sim.initial_pose(2);
}

TEST(PlantSimProcess, HeavierTruthSinksTheUncompensatedPlatformAtTheExpectedRate) {
  const std::string truth_path = testing::TempDir() + "/heavier_truth.yaml";
  const double mass_kg = 1.5 * Config().platform.platform_mass_kg;
  std::ofstream(truth_path) << "platform: {mass_kg: " << mass_kg
                            << "}\nactuators: {viscous_friction_nspm: 0.0}\n";
  constexpr double kT = 0.05;  // short: the pose, hence M and G, barely change
  const PlantTruth truth = LoadPlantTruth(Config(), truth_path);
  const Vector6d q0 = Config().plant_sim.initial_pose;
  const Vector6d qdd0 = ForwardDynamics(EvaluateDynamics(truth.platform, q0, Vector6d::Zero()),
                                        test::HoldingForce(Config().platform, q0));
  ASSERT_LT(qdd0(2), -1.0);  // it falls, at m/s^2
  const double expected = 0.5 * qdd0(2) * kT * kT;
  EXPECT_NEAR(SinkAfter(7705, truth_path, kT), expected, 0.03 * std::abs(expected));
  EXPECT_NEAR(SinkAfter(7706, "", kT), 0.0, 1e-6);
  std::remove(truth_path.c_str());
}

TEST(PlantSimProcess, BadTruthFileExitsNamingTheKey) {
  const std::string truth_path = testing::TempDir() + "/bad_truth.yaml";
  std::ofstream(truth_path) << "platform: {payload: {mass_kg: -1}}\n";
  const std::string log_path = testing::TempDir() + "/bad_truth.log";
  const std::string command = std::string(PLANT_SIM_BIN) + " --truth " + truth_path +
                              " --mode lockstep --duration 0.1 > " + log_path + " 2>&1";
  EXPECT_EQ(WEXITSTATUS(std::system(command.c_str())), 2);
  std::ifstream in(log_path);
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_NE(text.str().find("truth.platform.payload.mass_kg"), std::string::npos) << text.str();
  std::remove(truth_path.c_str());
  std::remove(log_path.c_str());
}

TEST(PlantSimProcess, LockstepTimeoutExitsNamingWhatItWaitedFor) {
  std::ifstream in(DefaultConfigPath());
  std::stringstream text;
  text << in.rdbuf();
  std::string yaml = text.str();
  const std::string key = "lockstep_timeout_s: ";
  const size_t at = yaml.find(key);
  ASSERT_NE(at, std::string::npos);
  yaml.replace(at, yaml.find('\n', at) - at, key + "0.3");
  const std::string path = ::testing::TempDir() + "plant_sim_timeout.yaml";
  std::ofstream(path) << yaml;
  const std::string url = PrivateLcmUrl(7703);
  Stack stack(url, false);
  test::ChildProcess sim({PLANT_SIM_BIN, "--config", path, "--lcm-url", url, "--mode", "lockstep",
                          "--duration", "1", "--log-level", "warn"});
  stack.SpinUntilExit(&sim, 10.0);
  EXPECT_EQ(sim.Wait(), 3);
  ASSERT_FALSE(stack.health.empty());
  EXPECT_EQ(stack.health.back().state, static_cast<int8_t>(health_t::STATE_FAULT));
  EXPECT_NE(stack.health.back().last_error.find("sample_utime 0"), std::string::npos)
      << stack.health.back().last_error;
  EXPECT_NE(stack.health.back().last_error.find(Config().lcm.channels.command_safe),
            std::string::npos);
}

}  // namespace
}  // namespace stewart
