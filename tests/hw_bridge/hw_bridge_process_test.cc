// End to end: hw_emulator (the device) and hw_bridge as processes, the test
// as the rest of the stack: it publishes force_command_t on CMD_SAFE computed
// from the sensor_t it receives, and checks what comes out.
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <string>
#include <thread>
#include <vector>

#include "stewart/config/config_loader.h"
#include "stewart/force_command_t.hpp"
#include "stewart/health_t.hpp"
#include "stewart/model/dynamics.h"
#include "stewart/model/kinematics.h"
#include "stewart/node/lcm_handle.h"
#include "stewart/sensor_t.hpp"
#include "stewart/test_support/child_process.h"
#include "stewart/test_support/fake_safety_session.h"

extern char** environ;

namespace stewart {
namespace {

using Clock = std::chrono::steady_clock;

class Stack {
 public:
  explicit Stack(int lcm_port) : config_(LoadStackConfig(DefaultConfigPath())) {
    config_.lcm.url = PrivateLcmUrl(lcm_port);
    lcm_ = MakeLcm(config_.lcm.url);
    safety_ = std::make_unique<test::FakeSafetySession>(lcm_.get(), config_.lcm.channels.supervisor,
                                                        config_.lcm.channels.command_safe);
    lcm_->subscribe(config_.lcm.channels.sensors, &Stack::OnSensor, this)->setQueueCapacity(1000);
    lcm_->subscribe(config_.lcm.channels.health, &Stack::OnHealth, this);
    const DynamicsTerms terms =
        EvaluateDynamics(config_.platform, config_.home_pose, Vector6d::Zero());
    f_hold_ = InverseDynamics(terms, Vector6d::Zero());
  }

  /// Runs for `seconds`, answering every sample with f_hold + extra (or
  /// nothing when `command` is false).
  void Run(double seconds, bool command, double extra_n = 0.0) {
    command_ = command;
    extra_n_ = extra_n;
    const auto end = Clock::now() + std::chrono::duration<double>(seconds);
    while (Clock::now() < end) lcm_->handleTimeout(2);
  }

  std::vector<sensor_t> sensors;
  std::vector<health_t> health;  // hw_bridge's only
  StackConfig config_;

 private:
  void OnSensor(const lcm::ReceiveBuffer*, const std::string&, const sensor_t* msg) {
    sensors.push_back(*msg);
    if (!command_) return;
    force_command_t cmd{};
    cmd.utime = msg->utime;
    cmd.sample_utime = msg->utime;
    for (int i = 0; i < 6; ++i) cmd.force_n[i] = f_hold_(i) + extra_n_;
    safety_->Publish(cmd);
  }
  void OnHealth(const lcm::ReceiveBuffer*, const std::string&, const health_t* msg) {
    if (msg->name == "hw_bridge") health.push_back(*msg);
  }

  std::unique_ptr<lcm::LCM> lcm_;
  std::unique_ptr<test::FakeSafetySession> safety_;
  Vector6d f_hold_;
  bool command_ = false;
  double extra_n_ = 0.0;
};

int64_t Counter(const health_t& h, const std::string& name) {
  for (int i = 0; i < h.num_counters; ++i) {
    if (h.counter_names[static_cast<std::size_t>(i)] == name) {
      return h.counter_values[static_cast<std::size_t>(i)];
    }
  }
  return -1;
}

double MeanLegLength(const std::vector<sensor_t>& s, std::size_t from, std::size_t to) {
  double sum = 0.0;
  for (std::size_t k = from; k < to; ++k) {
    for (double l : s[k].leg_length_m) sum += l;
  }
  return sum / (6.0 * static_cast<double>(to - from));
}

void ExpectSaneSamples(const Stack& stack, std::size_t held) {
  const Vector6d home_lengths = InverseKinematics(stack.config_.platform, stack.config_.home_pose);
  const PlatformParams& p = stack.config_.platform;
  ASSERT_GT(stack.sensors.size(), held);
  for (std::size_t k = 0; k < stack.sensors.size(); ++k) {
    const sensor_t& s = stack.sensors[k];
    EXPECT_EQ(s.sample_utime, s.utime);
    if (k > 0) {
      EXPECT_GT(s.utime, stack.sensors[k - 1].utime);
      EXPECT_GT(s.seq, stack.sensors[k - 1].seq);
    }
    for (int i = 0; i < 6; ++i) {
      ASSERT_TRUE(std::isfinite(s.leg_length_m[i]));
      EXPECT_GT(s.leg_length_m[i], p.leg_min_length_m - 1e-3);
      EXPECT_LT(s.leg_length_m[i], p.leg_max_length_m + 1e-3);
      // Gravity compensation holds the home pose (to a few ADC counts).
      if (k < held) {
        EXPECT_NEAR(s.leg_length_m[i], home_lengths(i), 2e-3);
      }
    }
    for (int i = 0; i < 3; ++i) {
      ASSERT_TRUE(std::isfinite(s.accel_mps2[i]) && std::isfinite(s.gyro_radps[i]));
    }
    // The IMU is checked where the platform is held still. When the commands
    // stop and the device zeroes the drive, the lead screws lock the moving
    // legs (Plant's lock: the end-stop spring and damper, c / m ~ 1e4 1/s):
    // a sample that falls in that sub-millisecond transient truly reads a
    // deceleration of a g or more, at the sample where the lock engages.
    if (k < held) {
      EXPECT_NEAR(s.accel_mps2[2], p.gravity_mps2, 1.0) << "sample " << k;
      EXPECT_LT(std::abs(s.gyro_radps[0]), 0.1) << "sample " << k;
    }
    EXPECT_EQ(s.status & sensor_t::STATUS_LEG_FAULT, 0);
  }
}

void ExerciseLink(Stack* stack, bool expect_lost) {
  // Gravity compensation: holds. At least 0.8 s and 300 samples (0.3 s at
  // the device's 1 kHz), waiting up to 5 s for them: under a loaded CI the
  // rates sag and process start-up eats into a fixed window; the assertions
  // are about behaviour, not speed.
  const auto hold_start = std::chrono::steady_clock::now();
  stack->Run(0.8, true);
  while (stack->sensors.size() < 300 &&
         std::chrono::steady_clock::now() < hold_start + std::chrono::seconds(5)) {
    stack->Run(0.05, true);
  }
  const std::size_t held = stack->sensors.size();
  ASSERT_GT(held, 100U)
      << "sensor_t is not flowing: " << held << " samples in "
      << std::chrono::duration<double>(std::chrono::steady_clock::now() - hold_start).count()
      << " s";
  const double before = MeanLegLength(stack->sensors, held - 50, held);
  // +0.06 N on every leg for 0.3 s, then commands stop: the bridge goes
  // stale after command_timeout_s and the locked legs hold. Against the legs'
  // friction (2 N s/m) the legs rise at up to 30 mm/s, under the bridge's
  // guard (guard.leg_speed_cap_mps, 50 mm/s; a harder push trips it: the
  // trust test). The push lasts 300 device samples (each answered by a
  // command), not 0.3 s of wall time: a loaded machine may stall the link
  // for a while, and the test is about the effect of the commands, not the
  // link's speed.
  const std::size_t push_start = stack->sensors.size();
  const auto push_deadline = std::chrono::steady_clock::now() + std::chrono::seconds(3);
  while (stack->sensors.size() < push_start + 300 &&
         std::chrono::steady_clock::now() < push_deadline) {
    stack->Run(0.005, true, 0.06);
  }
  const std::size_t health_at_stop = stack->health.size();
  // Commands stopped: at least 0.8 s (past command_timeout_s) and 300 more
  // samples, waiting up to 5 s for them.
  const std::size_t stop_start = stack->sensors.size();
  const auto stop_time = std::chrono::steady_clock::now();
  stack->Run(0.8, false);
  while (stack->sensors.size() < stop_start + 300 &&
         std::chrono::steady_clock::now() < stop_time + std::chrono::seconds(5)) {
    stack->Run(0.05, false);
  }
  const std::size_t end = stack->sensors.size();
  ASSERT_GT(end, held + 150);
  const double hold_a = MeanLegLength(stack->sensors, end - 150, end - 100);
  const double hold_b = MeanLegLength(stack->sensors, end - 50, end);
  EXPECT_GT(hold_a, before + 5e-3);   // it rose: the commands reached the device
  EXPECT_NEAR(hold_a, hold_b, 2e-4);  // and now it holds
  ExpectSaneSamples(*stack, held);
  ASSERT_FALSE(stack->health.empty());
  const health_t& h = stack->health.back();
  // The bridge must have reported the stale command (DEGRADED, zero drive).
  // A heartbeat in between may report a momentary link drop instead when a
  // loaded machine starves the emulator for > link_timeout_s, so the report
  // is looked for among the heartbeats after the commands stopped.
  bool stale_reported = false;
  for (std::size_t k = health_at_stop; k < stack->health.size(); ++k) {
    const health_t& hh = stack->health[k];
    stale_reported = stale_reported || (hh.state == health_t::STATE_DEGRADED &&
                                        hh.last_error.find("stale") != std::string::npos);
  }
  EXPECT_TRUE(stale_reported) << "last: state " << int{h.state} << ", " << h.last_error;
  EXPECT_EQ(Counter(h, "zero_drive"), 1);
  EXPECT_GT(Counter(h, "zero_drive_frames"), 50);
  EXPECT_GT(Counter(h, "commands_accepted"), 100);
  EXPECT_EQ(Counter(h, "guard_trips"), 0);
  EXPECT_EQ(Counter(h, "corrupt_frames"), 0);
  if (expect_lost) {
    EXPECT_GT(Counter(h, "lost_frames"), 0);
  }
  // Round trip measured at some point and loopback-plausible (< 50 ms).
  int64_t rtt_samples = 0;
  for (const health_t& hh : stack->health) {
    if (Counter(hh, "rtt_samples") > 0) {
      ++rtt_samples;
      EXPECT_LT(Counter(hh, "rtt_us_mean"), 50000);
    }
  }
  EXPECT_GT(rtt_samples, 0);
}

TEST(HwBridgeProcess, UdpEmulatorEndToEnd) {
  Stack stack(7760);
  const std::string url = stack.config_.lcm.url;
  test::ChildProcess emulator({HW_EMULATOR_EXE, "--transport", "udp", "--device-port", "17620",
                               "--host-port", "17621", "--drop-every", "97", "--log-level",
                               "warn"});
  test::ChildProcess bridge({HW_BRIDGE_EXE, "--lcm-url", url, "--device-port", "17620",
                             "--local-port", "17621", "--log-level", "warn"});
  ASSERT_TRUE(emulator.started());
  ASSERT_TRUE(bridge.started());
  stack.Run(0.3, false);  // start-up; the device holds with zero drive meanwhile
  ExerciseLink(&stack, true);
  EXPECT_TRUE(emulator.running());
  EXPECT_TRUE(bridge.running());
}

TEST(HwBridgeProcess, SerialOverPtyEndToEnd) {
  Stack stack(7761);
  const std::string url = stack.config_.lcm.url;
  const std::string link = "/tmp/hw_bridge_test_" + std::to_string(getpid()) + ".pty";
  test::ChildProcess emulator(
      {HW_EMULATOR_EXE, "--transport", "pty", "--pty-link", link, "--log-level", "warn"});
  ASSERT_TRUE(emulator.started());
  for (int i = 0; i < 200 && access(link.c_str(), F_OK) != 0; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ASSERT_EQ(access(link.c_str(), F_OK), 0) << "emulator did not create " << link;
  test::ChildProcess bridge({HW_BRIDGE_EXE, "--lcm-url", url, "--transport", "serial",
                             "--serial-device", link, "--log-level", "warn"});
  ASSERT_TRUE(bridge.started());
  stack.Run(0.3, false);
  ExerciseLink(&stack, false);
  EXPECT_TRUE(bridge.running());
}

TEST(HwBridgeProcess, BadConfigExitsWithStatus2) {
  const std::string path = "/tmp/hw_bridge_bad_" + std::to_string(getpid()) + ".yaml";
  {
    FILE* f = std::fopen(path.c_str(), "w");
    ASSERT_NE(f, nullptr);
    std::fputs("hw_bridge: {transport: carrier_pigeon}\n", f);
    std::fclose(f);
  }
  pid_t pid = -1;
  std::string exe = HW_BRIDGE_EXE, flag = "--config", level = "--log-level", off = "off";
  std::string p = path;
  char* argv[] = {exe.data(), flag.data(), p.data(), level.data(), off.data(), nullptr};
  ASSERT_EQ(posix_spawn(&pid, argv[0], nullptr, nullptr, argv, environ), 0);
  int status = 0;
  waitpid(pid, &status, 0);
  std::remove(path.c_str());
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 2);
}

// The pot calibration's guard flag goes with bring-up and replaces its margin;
// either misuse stops the bridge before it opens a socket, exit 2.
TEST(HwBridgeProcess, TheEndSearchFlagOnlyWithBringupAndWithoutAMargin) {
  const auto exit_code = [](std::vector<std::string> args) {
    args.insert(args.begin(), HW_BRIDGE_EXE);
    args.push_back("--log-level");
    args.push_back("off");
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    pid_t pid = -1;
    if (posix_spawn(&pid, argv[0], nullptr, nullptr, argv.data(), environ) != 0) return -1;
    int status = 0;
    waitpid(pid, &status, 0);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  };
  EXPECT_EQ(exit_code({"--bringup-end-search", "0.004"}), 2);
  EXPECT_EQ(exit_code({"--bringup", "--bringup-end-search", "0.004", "--bringup-margin", "0.01"}),
            2);
  EXPECT_EQ(exit_code({"--bringup", "--bringup-end-search", "-0.004"}), 2);
}

}  // namespace
}  // namespace stewart
