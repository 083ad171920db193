// hw_bridge killed (SIGKILL) and restarted while the platform moves, with the
// real processes: hw_emulator (the device, with its ground truth), hw_bridge,
// safety, controller (paper scenario), estimator and the logger, on a private
// LCM URL and private device ports, the supervisor armed at start-up as in
// simulation. The device must follow the new bridge (docs/wire-protocol.md,
// "Sessions"): it leaves WATCHDOG within kLeaveWatchdogBoundMs of stack time
// after the new bridge's first sample, and the new bridge forwards the safe
// commands again (health zero_drive 0) within kCommandedBoundS of wall time
// after its start. The supervisor latches HOLD on the bridge's restart (its
// heartbeat sequence starts over: "hw_bridge restarted"); the test then
// resumes it as an operator would, with stewart_ctl reset and resume, and
// the platform must move on.
// Every limit must hold on the emulator's recorded ground truth, the kill
// and the restart included.
//
// LCM port 8100, device UDP ports 8110 (device) and 8111 (bridge). Holds the
// launcher lock: a real-time stack.
#include <gtest/gtest.h>
#include <signal.h>
#include <stdio.h>
#include <sys/wait.h>

#include <chrono>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "stewart/config/config_loader.h"
#include "stewart/health_t.hpp"
#include "stewart/node/lcm_handle.h"
#include "stewart/node/lcm_receiver.h"
#include "stewart/sensor_t.hpp"
#include "stewart/state_t.hpp"
#include "stewart/supervisor_state_t.hpp"
#include "stewart/test_support/child_process.h"
#include "stewart/test_support/recorded_run.h"
#include "stewart/test_support/stack_launch.h"

namespace stewart {
namespace {

using Clock = std::chrono::steady_clock;

constexpr int kLcmPort = 8100;
constexpr int kDevicePort = 8110;  // the bridge binds kDevicePort + 1
// The device adopts the new bridge's session with its first zero-drive frame
// (its watchdog expired long ago) and echoes it in the next sample: a few
// samples. The bound leaves room for a descheduled process on 2 shared cores.
constexpr double kLeaveWatchdogBoundMs = 20.0;
// Process start, config, LCM, the session handshake and the next heartbeat
// (health.rates.health_hz 2 Hz: up to 0.5 s late by itself).
constexpr double kCommandedBoundS = 2.0;

int64_t Counter(const health_t& h, const std::string& name) {
  for (int i = 0; i < h.num_counters; ++i) {
    if (h.counter_names[static_cast<std::size_t>(i)] == name) {
      return h.counter_values[static_cast<std::size_t>(i)];
    }
  }
  return -1;
}

struct Bus {
  void OnSensor(const lcm::ReceiveBuffer*, const std::string&, const sensor_t* m) {
    sensors.push_back(*m);
  }
  void OnHealth(const lcm::ReceiveBuffer*, const std::string&, const health_t* m) {
    if (m->name == "hw_bridge") bridge_health.push_back({Clock::now(), *m});
  }
  void OnSupervisor(const lcm::ReceiveBuffer*, const std::string&, const supervisor_state_t* m) {
    supervisor = *m;
    have_supervisor = true;
  }
  void OnTruth(const lcm::ReceiveBuffer*, const std::string&, const state_t* m) { truth = *m; }

  std::vector<sensor_t> sensors;
  std::vector<std::pair<Clock::time_point, health_t>> bridge_health;
  supervisor_state_t supervisor{};
  bool have_supervisor = false;
  state_t truth{};
};

struct CtlResult {
  int exit_code = -1;
  std::string out;
};

/// stewart_ctl `args`, as an operator types it.
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

class HwBridgeRestart : public test::WithRunFolder<::testing::Test> {
 protected:
  HwBridgeRestart() : WithRunFolder("stewart_hw_bridge_restart") {}
};

TEST_F(HwBridgeRestart, TheDeviceFollowsARestartedBridgeAndTheLimitsHold) {
  test::LauncherLock lock;  // a real-time stack: no other stack beside it
  const StackConfig config = LoadStackConfig(DefaultConfigPath());
  const auto& ch = config.lcm.channels;
  const std::string url = PrivateLcmUrl(kLcmPort);
  const std::string log_path = run_folder_ + "/log.lcm";
  const std::string overlay = test::WriteAutoArmOverlay(
      run_folder_, "hw_bridge:\n  device_port: " + std::to_string(kDevicePort) +
                       "\n  local_port: " + std::to_string(kDevicePort + 1) + "\n");
  const auto with = [&](std::vector<std::string> argv) {
    return test::WithStackFlags(std::move(argv), url, overlay);
  };
  const std::string ctl_common = "--lcm-url '" + url + "' --overlay " + test::ShellQuote(overlay);

  LcmReceiver receiver(url);
  Bus bus;
  receiver.Subscribe(ch.sensors, &Bus::OnSensor, &bus);
  receiver.Subscribe(ch.health, &Bus::OnHealth, &bus);
  receiver.Subscribe(ch.supervisor, &Bus::OnSupervisor, &bus);
  receiver.Subscribe(ch.state_truth, &Bus::OnTruth, &bus);
  const auto pump_until = [&](auto done, double timeout_s) {
    return test::PumpUntil(&receiver, done, timeout_s);
  };
  const auto pump_for = [&](double seconds) { pump_until([] { return false; }, seconds); };

  test::StackWithoutPlant stack({LOGGER_PATH, SAFETY_PATH, CONTROLLER_PATH, ESTIMATOR_PATH}, url,
                                log_path, with);
  ASSERT_TRUE(stack.started());
  test::ChildProcess emulator(with({HW_EMULATOR_EXE}));
  auto bridge = std::make_unique<test::ChildProcess>(with({HW_BRIDGE_EXE}));
  ASSERT_TRUE(emulator.started() && bridge->started());

  // Armed and cruising towards x = 0.1 m.
  ASSERT_TRUE(pump_until(
      [&] {
        return bus.have_supervisor && bus.supervisor.state == supervisor_state_t::STATE_ARMED &&
               bus.truth.q[0] > 0.02;
      },
      30.0))
      << "the platform did not start moving: supervisor state " << int{bus.supervisor.state}
      << ", x " << bus.truth.q[0];
  const double x_at_kill = bus.truth.q[0];

  // The bridge dies mid-motion; the device's watchdog stops the legs.
  bridge->Stop(SIGKILL);
  pump_for(0.5);
  const std::size_t old_samples = bus.sensors.size();
  ASSERT_GT(old_samples, 1000u);

  bus.bridge_health.clear();
  const auto restarted = Clock::now();
  bridge = std::make_unique<test::ChildProcess>(with({HW_BRIDGE_EXE}));
  ASSERT_TRUE(bridge->started());

  // (1) The device leaves WATCHDOG: the new bridge's first sample still
  // reports it (the old bridge's silence), a sample within the bound must not.
  const auto watchdog_clear = [&](std::size_t from) {
    for (std::size_t k = from; k < bus.sensors.size(); ++k) {
      if ((bus.sensors[k].status & sensor_t::STATUS_DEVICE_WATCHDOG) == 0) return k;
    }
    return std::size_t{0};
  };
  const bool left =
      pump_until([&] { return watchdog_clear(old_samples) != 0; }, 3.0 + kCommandedBoundS);
  ASSERT_GT(bus.sensors.size(), old_samples) << "the new bridge published no sample";
  const sensor_t first_new = bus.sensors[old_samples];  // a copy: the vector grows
  const std::size_t watchdog_samples =
      (left ? watchdog_clear(old_samples) : bus.sensors.size()) - old_samples;
  ASSERT_TRUE(left) << "the device reported WATCHDOG on all " << bus.sensors.size() - old_samples
                    << " samples after the restart (first status " << first_new.status << ")";
  const double leave_ms =
      1e-3 * static_cast<double>(bus.sensors[watchdog_clear(old_samples)].utime - first_new.utime);
  EXPECT_LE(leave_ms, kLeaveWatchdogBoundMs);

  // (2) The new bridge forwards the safe commands: a heartbeat with the
  // device following its session and commands accepted. (Not "no zero
  // drive": the supervisor holds on the restart, the estimator restarts
  // after the gap, and the HOLD's brake, 0.5 s from its start, ends in the
  // drive-off command at about the time of the bridge's second heartbeat,
  // whose zero drive is then the stack's own choice, forwarded.)
  const auto commanded = [&] {
    for (const auto& [at, h] : bus.bridge_health) {
      const bool device_follows = Counter(h, "link_session") != 0 &&
                                  Counter(h, "device_session") == Counter(h, "link_session");
      const bool forwarded = Counter(h, "zero_drive") == 0 ||
                             h.last_error.find("drive_off safe command") != std::string::npos;
      if (device_follows && forwarded && Counter(h, "commands_accepted") > 0) return at;
    }
    return Clock::time_point{};
  };
  ASSERT_TRUE(pump_until([&] { return commanded() != Clock::time_point{}; }, 5.0))
      << "the new bridge never drove the device: last error '"
      << (bus.bridge_health.empty() ? std::string("no heartbeat")
                                    : bus.bridge_health.back().second.last_error)
      << "'";
  const double commanded_s = std::chrono::duration<double>(commanded() - restarted).count();
  EXPECT_LE(commanded_s, kCommandedBoundS);
  const health_t h = bus.bridge_health.back().second;  // a copy: the vector grows
  EXPECT_EQ(Counter(h, "device_session"), Counter(h, "link_session"));
  EXPECT_NE(Counter(h, "link_session"), 0);

  // (3) The supervisor held on the loss of the sensors: the operator
  // acknowledges and resumes, as with any HOLD; the platform moves on.
  pump_for(0.5);
  const int8_t state_after_restart = bus.supervisor.state;
  if (state_after_restart == supervisor_state_t::STATE_HOLD) {
    EXPECT_EQ(Ctl("reset " + ctl_common).exit_code, 0);
    const CtlResult resume = Ctl("resume " + ctl_common);
    EXPECT_EQ(resume.exit_code, 0) << resume.out;
  }
  ASSERT_TRUE(
      pump_until([&] { return bus.supervisor.state == supervisor_state_t::STATE_ARMED; }, 5.0))
      << "not armed again: " << bus.supervisor.reason;
  const double x_resumed = bus.truth.q[0];
  ASSERT_TRUE(pump_until([&] { return bus.truth.q[0] > x_resumed + 0.01; }, 5.0))
      << "the platform did not move on: x " << bus.truth.q[0] << " from " << x_resumed;
  std::printf(
      "[hw_bridge restart] killed at x = %.4f m; the device left WATCHDOG %.1f ms (stack time, "
      "%zu samples) after the new bridge's first sample; commands forwarded %.2f s after the "
      "restart; supervisor %s after the restart%s; x %.4f -> %.4f m after the resume\n",
      x_at_kill, leave_ms, watchdog_samples, commanded_s,
      state_after_restart == supervisor_state_t::STATE_HOLD ? "HOLD" : "not HOLD",
      state_after_restart == supervisor_state_t::STATE_HOLD ? " (reset, resume by stewart_ctl)"
                                                            : "",
      x_resumed, bus.truth.q[0]);
  std::printf(
      "[hw_bridge restart] new bridge: device_rx_session_rejected %ld, device_rx_lost %ld\n",
      static_cast<long>(Counter(h, "device_rx_session_rejected")),
      static_cast<long>(Counter(h, "device_rx_lost")));

  // (4) Every limit held on ground truth over the whole run.
  bridge->Stop(SIGTERM);
  emulator.Stop(SIGTERM);
  stack.logger.Stop(SIGTERM);
  const StackConfig run_config = LoadStackConfig(DefaultConfigPath(), {overlay});
  const test::RecordedRun run = test::ReadRecordedRun(log_path, run_config);
  ASSERT_NE(run.Worst(), nullptr);
  std::printf("[hw_bridge restart] %s\n", test::Describe(run).c_str());
  EXPECT_EQ(run.truth_non_finite, 0);
  test::ExpectWithinLimits(run);
}

}  // namespace
}  // namespace stewart
