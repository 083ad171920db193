// The stack on three hosts: network namespaces of this machine on one bridge
// (tools/netns_lab.sh), the device's host running plant_sim, the control
// host the estimator, controller and safety process, the observer the
// recorder and the monitor, joined by LCM multicast with ttl=1 across the
// bridge, started by tools/launch.sh --hosts. docs/operations.md, "Several
// hosts". The plant is not the model (--truth test::WriteMismatchedTruth).
//
// The lab here has names of its own (prefix stt, 10.78.0.0/24, groups
// 239.255.78.0/24), so a developer's lab (stw) may be up beside it. Needs
// root for the namespaces: skipped, saying so, without it. LCM ports
// 8012-8014 on the lab's groups.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/file.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "stewart/config/config_loader.h"
#include "stewart/force_command_t.hpp"
#include "stewart/health_t.hpp"
#include "stewart/node/lcm_handle.h"
#include "stewart/supervisor_state_t.hpp"
#include "stewart/test_support/child_process.h"
#include "stewart/test_support/health_counter.h"
#include "stewart/test_support/recorded_run.h"
#include "stewart/test_support/stack_launch.h"

namespace stewart {
namespace {

const char* const kLabEnv =
    "STEWART_LAB_PREFIX=stt STEWART_LAB_SUBNET=10.78.0 STEWART_LAB_GROUPS=239.255.78.0/24 ";

std::string LabUrl(int port, int ttl = 1) {
  return "udpm://239.255.78.1:" + std::to_string(port) + "?ttl=" + std::to_string(ttl);
}

int Lab(const std::string& args) {
  return test::Shell(std::string(kLabEnv) +
                     test::ShellQuote(std::string(STEWART_SOURCE_DIR) + "/tools/netns_lab.sh") +
                     " " + args + " >/dev/null 2>&1");
}

class HostsLab : public test::WithRunFolder<::testing::Test> {
 protected:
  HostsLab() : WithRunFolder("stewart_hosts") {}
  void SetUp() override {
    WithRunFolder::SetUp();
    if (geteuid() != 0) GTEST_SKIP() << "network namespaces need root; not run";
    if (test::Shell("ip netns add stt-probe >/dev/null 2>&1 && ip netns del stt-probe") != 0) {
      GTEST_SKIP() << "this kernel or container cannot make network namespaces; not run";
    }
    // One lab at a time: ctest runs this file's tests as separate processes.
    lab_lock_fd_ = ::open("/tmp/stewart_hosts_lab.lock", O_CREAT | O_RDWR | O_CLOEXEC, 0600);
    ASSERT_GE(lab_lock_fd_, 0);
    ASSERT_EQ(::flock(lab_lock_fd_, LOCK_EX), 0);
    Lab("down");  // a lab a killed run left behind
    ASSERT_EQ(Lab("up device control observer"), 0) << "tools/netns_lab.sh up failed";
    lab_up_ = true;
    hosts_ = run_folder_ + "/lab.hosts";
    std::ofstream(hosts_) << "host device   ip netns exec stt-device\n"
                             "host control  ip netns exec stt-control\n"
                             "host observer ip netns exec stt-observer\n"
                             "run plant_sim   device\n"
                             "run estimator   control\n"
                             "run controller  control\n"
                             "run safety      control\n"
                             "run logger      observer\n"
                             "run monitor     observer\n";
  }
  void TearDown() override {
    if (lab_up_) {
      EXPECT_EQ(Lab("down"), 0);
    }
    if (lab_lock_fd_ >= 0) ::close(lab_lock_fd_);  // releases the lock
    WithRunFolder::TearDown();
  }

  /// tools/launch.sh on the lab's URL; its output.
  test::LaunchResult Launch(const std::string& args, const std::string& url,
                            const std::string& name) {
    return test::RunLauncherOnUrl("--no-build --hosts " + test::ShellQuote(hosts_) + " " + args,
                                  url, run_folder_ + "/" + name, run_folder_ + "/" + name + ".out");
  }

  std::string hosts_;
  bool lab_up_ = false;
  int lab_lock_fd_ = -1;
};

TEST_F(HostsLab, NetworkCheckSaysWhoHearsWhom) {
  const test::LaunchResult ok = Launch("--check-network", LabUrl(8012), "check");
  const std::string out = test::ReadFile(ok.output_path);
  EXPECT_EQ(ok.exit_code, 0) << out;
  EXPECT_NE(out.find("device hears control"), std::string::npos) << out;
  EXPECT_NE(out.find("every host hears every host"), std::string::npos) << out;

  // ttl=0 across hosts: named, and nobody hears another host.
  const test::LaunchResult ttl0 = Launch("--check-network", LabUrl(8012, 0), "check_ttl0");
  const std::string out_ttl0 = test::ReadFile(ttl0.output_path);
  EXPECT_NE(ttl0.exit_code, 0) << out_ttl0;
  EXPECT_NE(out_ttl0.find("ttl=0"), std::string::npos) << out_ttl0;
}

TEST_F(HostsLab, NetworkCheckNamesAPartition) {
  ASSERT_EQ(Lab("link control down"), 0);
  const test::LaunchResult cut = Launch("--check-network", LabUrl(8012), "check_cut");
  const std::string out = test::ReadFile(cut.output_path);
  EXPECT_NE(cut.exit_code, 0) << out;
  EXPECT_NE(out.find("control hears device: 0 of"), std::string::npos) << out;
  EXPECT_NE(out.find("device hears control: 0 of"), std::string::npos) << out;
  EXPECT_NE(out.find("device hears observer: "), std::string::npos) << out;
  EXPECT_EQ(out.find("device hears observer: 0 of"), std::string::npos) << out;
}

TEST_F(HostsLab, NetworkCheckNamesAHostWithoutAMulticastRoute) {
  ASSERT_EQ(test::Shell("ip -n stt-control route del 224.0.0.0/4"), 0);
  const test::LaunchResult check = Launch("--check-network", LabUrl(8012), "check_route");
  const std::string out = test::ReadFile(check.output_path);
  EXPECT_NE(check.exit_code, 0) << out;
  EXPECT_NE(out.find("control: no route for 239.255.78.1"), std::string::npos) << out;
  EXPECT_NE(out.find("ip route add 224.0.0.0/4 dev IFACE"), std::string::npos) << out;
  // The hosts that have their route are checked still, and hear each other.
  EXPECT_NE(out.find("device hears observer: "), std::string::npos) << out;
  EXPECT_EQ(out.find("device hears observer: 0 of"), std::string::npos) << out;
  EXPECT_NE(out.find("device hears control: control sent no probes"), std::string::npos) << out;
}

TEST_F(HostsLab, NetworkCheckNamesAFirewallRuleOnTheHostThatHasIt) {
  if (test::Shell("command -v iptables >/dev/null") != 0) {
    GTEST_SKIP() << "iptables is not installed (tools/setup.sh installs it); not run";
  }
  ASSERT_EQ(test::Shell("ip netns exec stt-control iptables -A INPUT -p udp -j DROP"), 0);
  const test::LaunchResult check = Launch("--check-network", LabUrl(8012), "check_firewall");
  const std::string out = test::ReadFile(check.output_path);
  EXPECT_NE(check.exit_code, 0) << out;
  EXPECT_NE(out.find("control hears device: 0 of"), std::string::npos) << out;
  EXPECT_NE(out.find("control: a firewall rule drops packets"), std::string::npos) << out;
  EXPECT_NE(out.find("-A INPUT -p udp -j DROP"), std::string::npos) << out;
  // Only the host with the rule is named.
  EXPECT_EQ(out.find("device: a firewall rule"), std::string::npos) << out;
  EXPECT_EQ(out.find("observer: a firewall rule"), std::string::npos) << out;
}

TEST_F(HostsLab, PaperScenarioAcrossThreeHosts) {
  constexpr double kDurationS = 12.0;
  const test::LaunchResult run =
      Launch("--duration " + std::to_string(kDurationS) + " --no-report --truth " +
                 test::ShellQuote(test::WriteMismatchedTruth(run_folder_)),
             LabUrl(8013), "paper");
  ASSERT_EQ(run.exit_code, 0) << test::LaunchFailure(run);
  const std::string folder = run_folder_ + "/paper";
  EXPECT_NE(test::ReadFile(folder + "/run.yaml").find("hosts: "), std::string::npos);
  const StackConfig config = LoadStackConfig(folder + "/config.yaml");
  const test::RecordedRun recorded = test::ReadRecordedRun(folder + "/log.lcm", config);
  ASSERT_NE(recorded.Worst(), nullptr) << "nothing recorded on the observer";
  std::printf("[hosts] %s\n", test::Describe(recorded).c_str());
  // The loop's latency across the bridge, as the plant measured it
  // (docs/performance.md, "Latency across hosts").
  const std::string plant_log = test::ReadFile(folder + "/plant_sim.log");
  const size_t latency = plant_log.find("sample-to-command latency");
  ASSERT_NE(latency, std::string::npos) << "plant_sim.log has no latency line";
  std::printf("[hosts] plant_sim: %s\n",
              plant_log.substr(latency, plant_log.find('\n', latency) - latency).c_str());
  EXPECT_GE(static_cast<double>(recorded.truth_samples),
            0.95 * kDurationS * config.sensors.rate_hz);
  test::ExpectWithinLimits(recorded);
  EXPECT_GT(recorded.max_x, 0.05) << "the platform did not move";
}

/// What the device's side of the bus carries (its own group): the sensor
/// stream, and what reaches it from the control host through the relay.
struct DeviceSide {
  void OnSafe(const lcm::ReceiveBuffer*, const std::string&, const force_command_t* m) {
    ++safe_commands;
    if ((m->flags & force_command_t::FLAG_FALLBACK) != 0) ++fallback_commands;
  }
  void OnSupervisor(const lcm::ReceiveBuffer*, const std::string&, const supervisor_state_t* m) {
    supervisor = m->state;
    reason = m->reason;
    if (m->state == supervisor_state_t::STATE_HOLD) ++hold_states;
  }
  void OnHealth(const lcm::ReceiveBuffer*, const std::string&, const health_t* m) {
    if (m->name == "plant_sim") plant = *m;
    ++heartbeats_from[m->name];
  }
  int64_t safe_commands = 0, fallback_commands = 0, hold_states = 0;
  int8_t supervisor = -1;
  std::string reason;
  health_t plant{};
  std::map<std::string, int64_t> heartbeats_from;
};

/// The plant's sample-to-command latency over one phase, from its heartbeat
/// (a window of the last heartbeat period).
std::string Latency(const health_t& plant) {
  char s[96];
  std::snprintf(s, sizeof s, "p50 %.2f ms, p99 %.2f ms",
                1e-3 * double(test::HealthCounter(plant, "latency_p50_us")),
                1e-3 * double(test::HealthCounter(plant, "latency_p99_us")));
  return s;
}

// The device (plant_sim, real time) on one group, the control host
// (estimator, controller, safety) on another, and stewart_netrelay between
// them on the observer's host: the only path from one to the other. In
// turn: a clean relay; a congested link (2 ms + up to 1 ms jitter each way,
// 2 % loss); a slow link (40 ms each way: every command is older than the
// plant's command_timeout_s when it lands, so the plant's guard turns the
// actuators off and the lead screws hold); a partition (no relay for 2.5 s,
// beyond the supervisor's heartbeat timeout); and the link back. The
// supervisor must stay ARMED on the congested link, go to HOLD in the
// partition, stay there when the link is back until the operator resets
// and resumes, and then run again; limits hold on ground truth throughout.
TEST_F(HostsLab, DelayLossAndAPartitionBetweenControlAndDevice) {
  if (test::Shell("chrt -f 50 true && taskset -c 1 true") != 0) {
    GTEST_SKIP() << "needs SCHED_FIFO and a second CPU for a real-time loop, as tools/launch.sh";
  }
  const std::string kLoopCpu = "1";
  test::LauncherLock cores;  // real time: no other stack on the 2 cores
  const std::string device_url = "udpm://239.255.78.2:8014?ttl=1";
  const std::string control_url = LabUrl(8014);
  const std::string overlay = test::WriteAutoArmOverlay(run_folder_);
  const StackConfig config = LoadStackConfig(DefaultConfigPath(), {overlay});
  // As tools/launch.sh runs a real-time loop: on the last CPU, SCHED_FIFO
  // 50, so a busy machine (a build beside the test) does not stretch the
  // loop's latency.
  const auto on = [&](const std::string& host, const std::string& cpu,
                      const std::vector<std::string>& argv) {
    std::vector<std::string> full = {"/usr/bin/env", "ip",      "netns", "exec",
                                     "stt-" + host,  "taskset", "-c",    cpu,
                                     "chrt",         "-f",      "50"};
    full.insert(full.end(), argv.begin(), argv.end());
    return std::make_unique<test::ChildProcess>(full);
  };
  const auto stack_process = [&](const std::string& host, const std::string& url,
                                 std::vector<std::string> argv) {
    return on(host, kLoopCpu, test::WithStackFlags(std::move(argv), url, overlay));
  };
  // The relay stands in for the network, not for a host of the stack: on
  // the other CPU. On the loop's CPU, at the loop's priority, a relay
  // starting up (to change the link) held plant_sim's tick 8 ms and the
  // commands past the plant's command timeout, and its forwarding of every
  // message took the CPU the four loop processes share.
  const std::string kRelayCpu = "0";
  std::unique_ptr<lcm::LCM> lcm = MakeLcm(device_url);
  DeviceSide bus;
  const auto& ch = config.lcm.channels;
  lcm->subscribe(ch.command_safe, &DeviceSide::OnSafe, &bus)->setQueueCapacity(1000000);
  lcm->subscribe(ch.supervisor, &DeviceSide::OnSupervisor, &bus)->setQueueCapacity(100000);
  lcm->subscribe(ch.health, &DeviceSide::OnHealth, &bus)->setQueueCapacity(100000);
  const auto pump_until = [&](const std::function<bool()>& done, double timeout_s) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
    while (!done()) {
      if (std::chrono::steady_clock::now() > end) return false;
      lcm->handleTimeout(5);
    }
    return true;
  };
  const auto pump = [&](double seconds) { pump_until([] { return false; }, seconds); };
  // A new link is up once the relay has joined both groups: only then is the
  // old one stopped, so changing the link is not a partition of its own (a
  // relay started through ip netns exec, taskset and chrt on a busy machine
  // took longer than the plant's 50 ms command timeout).
  int relays_started = 0;
  const auto relay = [&](const std::string& delay_ms, const std::string& jitter_ms,
                         const std::string& loss) {
    const std::string ready = run_folder_ + "/relay" + std::to_string(++relays_started) + ".ready";
    auto process = on("observer", kRelayCpu,
                      {NETRELAY_PATH, "--a", device_url, "--b", control_url, "--delay-ms", delay_ms,
                       "--jitter-ms", jitter_ms, "--loss", loss, "--ready-file", ready});
    EXPECT_TRUE(
        pump_until([&] { return std::filesystem::exists(ready) || !process->running(); }, 10.0) &&
        process->running())
        << "the relay (" << delay_ms << " ms, " << jitter_ms << " ms, " << loss
        << ") did not come up";
    return process;
  };

  const std::string log_path = run_folder_ + "/device_side.lcm";
  test::ChildProcess logger(
      {LOGGER_PATH, "--lcm-url=" + device_url + "&recv_buf_size=4194304", "-f", log_path});
  auto safety = stack_process("control", control_url, {SAFETY_PATH});
  auto controller = stack_process("control", control_url, {CONTROLLER_PATH, "--scenario", "paper"});
  auto estimator = stack_process("control", control_url, {ESTIMATOR_PATH});
  auto link = relay("0", "0", "0");
  ASSERT_TRUE(pump_until(
      [&] {
        return bus.heartbeats_from["safety"] > 0 && bus.heartbeats_from["controller"] > 0 &&
               bus.heartbeats_from["estimator"] > 0;
      },
      15.0))
      << "the control host's heartbeats did not reach the device's group through the relay";
  auto plant = stack_process("device", device_url,
                             {PLANT_SIM_PATH, "--mode", "realtime", "--duration", "40", "--truth",
                              test::WriteMismatchedTruth(run_folder_)});

  // Clean relay: armed, nominal commands.
  ASSERT_TRUE(pump_until(
      [&] { return bus.supervisor == supervisor_state_t::STATE_ARMED && bus.safe_commands > 1000; },
      20.0))
      << "not armed through a clean relay (supervisor " << int(bus.supervisor) << ": " << bus.reason
      << ")";
  pump(2.0);
  const std::string clean = Latency(bus.plant);

  // Congested link: stays armed, commands keep being applied.
  link = relay("2", "1", "0.02");
  const int64_t holds_before = bus.hold_states;
  const int64_t timeouts_before = test::HealthCounter(bus.plant, "command_timeouts");
  pump(4.0);
  EXPECT_EQ(bus.hold_states, holds_before) << "HOLD on a congested link: " << bus.reason;
  EXPECT_EQ(int{bus.supervisor}, int{supervisor_state_t::STATE_ARMED}) << bus.reason;
  EXPECT_EQ(test::HealthCounter(bus.plant, "command_timeouts"), timeouts_before)
      << "the plant timed out commands on a 2 ms link";
  const std::string congested = Latency(bus.plant);

  // Slow link: the plant's guard refuses every command as too old.
  link = relay("40", "0", "0");
  pump(2.0);
  EXPECT_GT(test::HealthCounter(bus.plant, "command_timeouts"), timeouts_before)
      << "commands 80 ms old (round trip) were applied: command_timeout_s is "
      << config.plant_sim.command_timeout_s << " s";
  EXPECT_EQ(test::HealthCounter(bus.plant, "fallback_active"), 1);

  // Partition, then the link back.
  link.reset();  // SIGTERM: the relay is gone
  pump(2.5);
  link = relay("0", "0", "0");
  ASSERT_TRUE(pump_until([&] { return bus.supervisor == supervisor_state_t::STATE_HOLD; }, 5.0))
      << "no HOLD after a 2.5 s partition (supervisor " << int(bus.supervisor) << ": " << bus.reason
      << ")";
  const std::string hold_reason = bus.reason;
  pump(1.5);
  EXPECT_EQ(int{bus.supervisor}, int{supervisor_state_t::STATE_HOLD})
      << "the supervisor left HOLD without the operator: " << bus.reason;

  // The operator, at the control host: reset, then resume.
  const auto ctl = [&](const std::string& verb) {
    auto console = stack_process("control", control_url, {STEWART_CTL_PATH, verb});
    pump_until([&] { return !console->running(); }, 10.0);
    return console->running() ? -1 : console->exit_code();
  };
  EXPECT_EQ(ctl("reset"), 0);
  EXPECT_EQ(ctl("resume"), 0);
  const int64_t safe_at_resume = bus.safe_commands, fallback_at_resume = bus.fallback_commands;
  EXPECT_TRUE(pump_until([&] { return bus.supervisor == supervisor_state_t::STATE_ARMED; }, 5.0))
      << "not ARMED after the operator's resume: " << bus.reason;
  pump(2.0);
  const int64_t nominal_after =
      (bus.safe_commands - safe_at_resume) - (bus.fallback_commands - fallback_at_resume);
  EXPECT_GT(nominal_after, 1000) << "no nominal commands after the resume";
  EXPECT_EQ(test::HealthCounter(bus.plant, "fallback_active"), 0);

  plant.reset();
  link.reset();
  estimator.reset();
  controller.reset();
  safety.reset();
  pump(0.5);
  std::printf(
      "[hosts-link] sample to command at the plant: clean relay %s; 2 ms + 1 ms jitter, "
      "2 %% loss %s; partition: HOLD (%s)\n",
      clean.c_str(), congested.c_str(), hold_reason.c_str());
  std::fflush(stdout);

  const test::RecordedRun recorded = test::ReadRecordedRun(log_path, config);
  ASSERT_NE(recorded.Worst(), nullptr) << "nothing recorded on the device's group";
  std::printf("[hosts-link] %s\n", test::Describe(recorded).c_str());
  test::ExpectWithinLimits(recorded);
}

}  // namespace
}  // namespace stewart
