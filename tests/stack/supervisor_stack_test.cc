// The supervisor end to end, with the real processes (plant_sim in real
// time, estimator, controller, safety) and the operator's console
// stewart_ctl, on a private URL with authenticated channels: power-on is
// DISARMED (the drive off), `arm` moves the platform, a killed and
// restarted controller leaves it held (no automatic resume), `resume` is
// refused until `reset`, then ramps back to the filtered command with the
// scenario's clock where it was; `estop` turns the drive off and latches.
// LCM ports 7827 and 7828 (this folder owns 7820-7829).
#include <gtest/gtest.h>
#include <signal.h>
#include <stdio.h>
#include <sys/stat.h>
#include <sys/wait.h>

#include <algorithm>
#include <chrono>
#include <fstream>
#include <string>
#include <vector>

#include "stewart/config/config_loader.h"
#include "stewart/force_command_t.hpp"
#include "stewart/node/lcm_handle.h"
#include "stewart/node/message_auth.h"
#include "stewart/supervisor_state_t.hpp"
#include "stewart/test_support/child_process.h"
#include "stewart/test_support/stack_launch.h"

namespace stewart {
namespace {

constexpr int kPort = 7827;

struct Sink {
  void OnSafe(const lcm::ReceiveBuffer*, const std::string&, const force_command_t* msg) {
    safe.push_back(*msg);
  }
  void OnSupervisor(const lcm::ReceiveBuffer*, const std::string&, const supervisor_state_t* msg) {
    supervisor.push_back(*msg);
  }
  std::vector<force_command_t> safe;
  std::vector<supervisor_state_t> supervisor;
};

struct CtlResult {
  int exit_code = -1;
  std::string out;  // stdout: the state's name
};

/// Runs stewart_ctl with `args` and waits for it.
CtlResult Ctl(const std::string& args) {
  CtlResult r;
  FILE* pipe = ::popen((std::string(STEWART_CTL_PATH) + " " + args + " 2>/dev/null").c_str(), "r");
  if (pipe == nullptr) return r;
  char buffer[256];
  while (std::fgets(buffer, sizeof buffer, pipe) != nullptr) r.out += buffer;
  const int status = ::pclose(pipe);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  while (!r.out.empty() && (r.out.back() == '\n' || r.out.back() == ' ')) r.out.pop_back();
  return r;
}

bool DriveOff(const force_command_t& c) { return (c.flags & force_command_t::FLAG_DRIVE_OFF) != 0; }
bool Fallback(const force_command_t& c) { return (c.flags & force_command_t::FLAG_FALLBACK) != 0; }

TEST(SupervisorStack, ArmHoldAfterARestartResumeAndEstopWithTheConsole) {
  test::LauncherLock lock;  // a real-time stack: no other stack or browser beside it
  const StackConfig config = LoadStackConfig(DefaultConfigPath());
  const std::string url = PrivateLcmUrl(kPort);
  const std::string dir = ::testing::TempDir();
  const std::string key = dir + "supervisor_stack.key";
  std::ofstream(key) << "8f3a61c2d4e5f60718293a4b5c6d7e8f90a1b2c3d4e5f60718293a4b5c6d7e8f\n";
  ::chmod(key.c_str(), 0600);
  const std::string overlay = dir + "supervisor_stack_overlay.yaml";
  std::ofstream(overlay) << "lcm:\n  auth_key_file: \"" << key
                         << "\"\nsupervisor:\n  arming_ramp_s: 0.5\n";
  auto lcm = MakeLcm(url);
  Sink sink;
  lcm->subscribe(config.lcm.channels.command_safe, &Sink::OnSafe, &sink)->setQueueCapacity(100000);
  lcm->subscribe(config.lcm.channels.supervisor, &Sink::OnSupervisor, &sink)
      ->setQueueCapacity(100000);
  const std::vector<std::string> common = {"--lcm-url", url,           "--overlay",
                                           overlay,     "--log-level", "warn"};
  auto with = [&](std::vector<std::string> head) {
    head.insert(head.end(), common.begin(), common.end());
    return head;
  };
  const std::string ctl_common = "--lcm-url '" + url + "' --overlay " + overlay;
  test::ChildProcess safety(with({SAFETY_PATH}));
  auto controller =
      std::make_unique<test::ChildProcess>(with({CONTROLLER_PATH, "--scenario", "paper"}));
  test::ChildProcess estimator(with({ESTIMATOR_PATH}));
  test::ChildProcess plant(with({PLANT_SIM_PATH, "--mode", "realtime"}));
  ASSERT_TRUE(safety.started() && controller->started() && estimator.started() && plant.started());
  auto pump_for = [&](double seconds) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (std::chrono::steady_clock::now() < end) lcm->handleTimeout(10);
  };
  auto last_state = [&] {
    pump_for(0.2);
    return sink.supervisor.empty() ? int8_t{-1} : sink.supervisor.back().state;
  };

  // Power-on: DISARMED, the drive off, nothing moves by itself.
  pump_for(2.0);
  ASSERT_GT(sink.safe.size(), 1000u) << "the stack did not come up";
  EXPECT_TRUE(std::all_of(sink.safe.end() - 500, sink.safe.end(), DriveOff));
  EXPECT_EQ(Ctl("status " + ctl_common).out, "DISARMED");

  // Arm: the ramp, then the filtered command.
  const CtlResult arm = Ctl("arm " + ctl_common);
  ASSERT_EQ(arm.exit_code, 0) << arm.out;
  EXPECT_TRUE(arm.out == "ARMING" || arm.out == "ARMED") << arm.out;
  pump_for(2.0);
  EXPECT_EQ(last_state(), int8_t{supervisor_state_t::STATE_ARMED});
  ASSERT_TRUE(std::none_of(sink.safe.end() - 200, sink.safe.end(),
                           [](const force_command_t& c) { return DriveOff(c) || Fallback(c); }));
  const int64_t motion_before_us = sink.supervisor.back().motion_time_us;
  EXPECT_GT(motion_before_us, 1'500'000);

  // The controller dies and comes back: held, and it stays held.
  const size_t n_states = sink.supervisor.size();
  controller->Stop(SIGKILL);
  pump_for(0.5);
  EXPECT_EQ(last_state(), int8_t{supervisor_state_t::STATE_HOLD});
  {
    // Fault to hold, in stack time: the last filtered command, then the
    // watchdog's fallbacks for supervisor.fallback_latch_s, then HOLD.
    int64_t last_filtered = -1;
    for (const force_command_t& c : sink.safe) {
      if (!Fallback(c)) last_filtered = std::max(last_filtered, c.sample_utime);
    }
    int64_t hold_utime = -1;
    for (size_t i = n_states; i < sink.supervisor.size() && hold_utime < 0; ++i) {
      if (sink.supervisor[i].state == supervisor_state_t::STATE_HOLD) {
        hold_utime = sink.supervisor[i].utime;
      }
    }
    ASSERT_GT(last_filtered, 0);
    ASSERT_GT(hold_utime, 0);
    const double ms = 1e-3 * static_cast<double>(hold_utime - last_filtered);
    const double bound_ms =
        1e3 * (config.safety.stale_age_s + config.supervisor.fallback_latch_s) + 2.0;
    EXPECT_LE(ms, bound_ms);
    std::printf(
        "[supervisor] controller killed: HOLD %.1f ms (stack time) after the last "
        "filtered command (bound %.1f ms)\n",
        ms, bound_ms);
  }
  controller = std::make_unique<test::ChildProcess>(with({CONTROLLER_PATH, "--scenario", "paper"}));
  ASSERT_TRUE(controller->started());
  pump_for(2.0);
  const size_t n_held = sink.safe.size();
  pump_for(1.0);
  ASSERT_GT(sink.safe.size(), n_held + 500);
  EXPECT_TRUE(std::all_of(sink.safe.begin() + static_cast<long>(n_held), sink.safe.end(), Fallback))
      << "the platform moved again without an operator";
  EXPECT_EQ(Ctl("status " + ctl_common).out, "HOLD");
  const int64_t motion_held_us = sink.supervisor.back().motion_time_us;
  EXPECT_LT(motion_held_us - motion_before_us, 600'000);  // paused since the fault

  // Resume is refused until the fault is acknowledged.
  EXPECT_EQ(Ctl("resume " + ctl_common).exit_code, 5);
  EXPECT_EQ(Ctl("reset " + ctl_common).exit_code, 0);
  const CtlResult resume = Ctl("resume " + ctl_common);
  ASSERT_EQ(resume.exit_code, 0) << resume.out;
  pump_for(2.0);
  EXPECT_EQ(last_state(), int8_t{supervisor_state_t::STATE_ARMED});
  EXPECT_TRUE(std::none_of(sink.safe.end() - 200, sink.safe.end(), Fallback));
  // The motion clock went on from where it paused (the restarted
  // controller takes the scenario up there, not at t = 0).
  EXPECT_GT(sink.supervisor.back().motion_time_us, motion_held_us + 1'000'000);

  // E-stop: the drive off, latched; arm refused until reset.
  EXPECT_EQ(Ctl("estop " + ctl_common).out, "ESTOP");
  pump_for(0.5);
  const size_t n_estop = sink.safe.size();
  pump_for(0.5);
  EXPECT_TRUE(
      std::all_of(sink.safe.begin() + static_cast<long>(n_estop), sink.safe.end(), DriveOff));
  EXPECT_EQ(Ctl("arm " + ctl_common).exit_code, 5);
  EXPECT_EQ(Ctl("reset " + ctl_common).out, "DISARMED");

  // A forged operator command (no MAC) is dropped and counted.
  EXPECT_EQ(Ctl("arm --lcm-url '" + url + "' --timeout 0.5").exit_code, 1);
  pump_for(0.3);
  EXPECT_EQ(sink.supervisor.back().state, int8_t{supervisor_state_t::STATE_DISARMED});
  EXPECT_GE(sink.supervisor.back().operator_commands_rejected, 1);
}

// The dead-man: with supervisor.operator_timeout_s set, an armed platform
// holds when the operator's console stops sending heartbeats.
TEST(SupervisorStack, TheDeadManHoldsWhenTheOperatorsHeartbeatsStop) {
  test::LauncherLock lock;  // a real-time stack: no other stack or browser beside it
  const StackConfig config = LoadStackConfig(DefaultConfigPath());
  const std::string url = PrivateLcmUrl(kPort + 1);
  const std::string overlay = ::testing::TempDir() + "supervisor_deadman_overlay.yaml";
  std::ofstream(overlay) << "supervisor:\n  arming_ramp_s: 0.2\n  operator_timeout_s: 0.5\n";
  auto lcm = MakeLcm(url);
  Sink sink;
  lcm->subscribe(config.lcm.channels.supervisor, &Sink::OnSupervisor, &sink)
      ->setQueueCapacity(100000);
  const std::vector<std::string> common = {"--lcm-url", url,           "--overlay",
                                           overlay,     "--log-level", "warn"};
  auto with = [&](std::vector<std::string> head) {
    head.insert(head.end(), common.begin(), common.end());
    return head;
  };
  const std::string ctl_common = "--lcm-url '" + url + "' --overlay " + overlay;
  test::ChildProcess safety(with({SAFETY_PATH}));
  test::ChildProcess controller(with({CONTROLLER_PATH, "--scenario", "paper"}));
  test::ChildProcess estimator(with({ESTIMATOR_PATH}));
  test::ChildProcess plant(with({PLANT_SIM_PATH, "--mode", "realtime"}));
  ASSERT_TRUE(safety.started() && controller.started() && estimator.started() && plant.started());
  auto pump_for = [&](double seconds) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (std::chrono::steady_clock::now() < end) lcm->handleTimeout(10);
  };
  pump_for(1.5);
  // A console that keeps the dead-man fed, then the arm.
  auto console = std::make_unique<test::ChildProcess>(
      std::vector<std::string>{STEWART_CTL_PATH, "heartbeat", "--period", "0.1", "--lcm-url", url,
                               "--overlay", overlay, "--log-level", "warn"});
  ASSERT_TRUE(console->started());
  pump_for(0.3);
  ASSERT_EQ(Ctl("arm " + ctl_common).exit_code, 0);
  pump_for(1.5);
  ASSERT_FALSE(sink.supervisor.empty());
  EXPECT_EQ(sink.supervisor.back().state, int8_t{supervisor_state_t::STATE_ARMED});
  // The console goes away: held within the timeout (plus a poll).
  console->Stop(SIGKILL);
  const auto killed = std::chrono::steady_clock::now();
  bool held = false;
  while (!held && std::chrono::steady_clock::now() - killed < std::chrono::seconds(2)) {
    lcm->handleTimeout(10);
    held = sink.supervisor.back().state == supervisor_state_t::STATE_HOLD;
  }
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - killed).count();
  ASSERT_TRUE(held) << "still " << int{sink.supervisor.back().state} << " after 2 s";
  EXPECT_GE(s, 0.35);
  EXPECT_LE(s, 1.0);
  EXPECT_NE(sink.supervisor.back().reason.find("dead-man"), std::string::npos)
      << sink.supervisor.back().reason;
  std::printf("[supervisor] dead-man: HOLD %.2f s after the last heartbeat source died\n", s);
}

}  // namespace
}  // namespace stewart
