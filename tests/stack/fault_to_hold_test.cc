// Time from each fault to the safe stop and to HOLD, measured over LCM with
// the real processes (plant_sim in real time, estimator, controller, safety,
// the operator's console stewart_ctl): a fresh stack per fault, armed by the
// supervisor (auto_arm, as tools/launch.sh has it in simulation), the fault
// injected once it is ARMED. Measured from the fault (its wall time, and the
// stack time of the first sensor sample after it) to
//   (a) the first CMD_SAFE carrying FLAG_FALLBACK of those that last (the
//       safe stop), and
//   (b) the first supervisor_state_t in HOLD (ESTOP for the estop).
// Each test prints one "[fault-to-hold]" line and bounds both from the
// config (docs/operations.md, "Arming and e-stop", the table of faults).
// LCM ports 7950-7957, one per test.
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "stewart/config/config_loader.h"
#include "stewart/force_command_t.hpp"
#include "stewart/health_t.hpp"
#include "stewart/node/lcm_handle.h"
#include "stewart/operator_command_t.hpp"
#include "stewart/sensor_t.hpp"
#include "stewart/state_t.hpp"
#include "stewart/supervisor_state_t.hpp"
#include "stewart/test_support/child_process.h"
#include "stewart/test_support/health_counter.h"
#include "stewart/test_support/stack_launch.h"

namespace stewart {
namespace {

constexpr int kPortBase = 7950;

int64_t WallUs() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

template <typename Msg>
struct Received {
  Msg msg;
  int64_t recv_us;  // wall time the test received it (LCM's receive time)
};

bool Fallback(const force_command_t& c) { return (c.flags & force_command_t::FLAG_FALLBACK) != 0; }

/// What the test hears of the stack, with receive times.
struct Bus {
  void OnSensor(const lcm::ReceiveBuffer* b, const std::string&, const sensor_t* m) {
    sensors.push_back({*m, b->recv_utime});
  }
  void OnSafe(const lcm::ReceiveBuffer* b, const std::string&, const force_command_t* m) {
    safe.push_back({*m, b->recv_utime});
  }
  void OnSupervisor(const lcm::ReceiveBuffer* b, const std::string&, const supervisor_state_t* m) {
    supervisor.push_back({*m, b->recv_utime});
  }
  void OnHealth(const lcm::ReceiveBuffer* b, const std::string&, const health_t* m) {
    health.push_back({*m, b->recv_utime});
  }
  void OnOperator(const lcm::ReceiveBuffer* b, const std::string&, const operator_command_t* m) {
    operators.push_back({*m, b->recv_utime});
  }
  std::vector<Received<sensor_t>> sensors;
  std::vector<Received<force_command_t>> safe;
  std::vector<Received<supervisor_state_t>> supervisor;
  std::vector<Received<health_t>> health;
  std::vector<Received<operator_command_t>> operators;
};

/// The measured times of one fault (ms; nullopt: never seen).
struct Times {
  int64_t fault_wall_us = 0;
  int64_t fault_stack_us = -1;  // the first sensor sample received after the fault
  std::optional<double> stop_stack_ms, stop_wall_ms;
  std::optional<double> hold_stack_ms, hold_wall_ms;
  std::string hold_reason;
  // Messages the test did not receive (gaps in seq): a measure may be late.
  int64_t lost_sensors = 0, lost_safe = 0, lost_supervisor = 0;
};

template <typename Msg>
int64_t Lost(const std::vector<Received<Msg>>& received) {
  int64_t lost = 0;
  for (size_t i = 1; i < received.size(); ++i) {
    const int64_t step = received[i].msg.seq - received[i - 1].msg.seq;
    if (step > 1) lost += step - 1;
  }
  return lost;
}

std::string Ms(const std::optional<double>& v) {
  if (!v) return "never";
  char s[32];
  std::snprintf(s, sizeof s, "%.1f ms", *v);
  return s;
}

/// The real processes on a private URL, with the test's overlay.
class Stack {
 public:
  /// `overlay_yaml` is added to the supervisor's auto-arm overlay;
  /// `controller_overlay_yaml`, when not empty, is one more overlay for the
  /// controller alone.
  Stack(const std::string& name, int port, const std::string& overlay_yaml,
        const std::string& controller_overlay_yaml = "")
      : url_(PrivateLcmUrl(port)), dir_(::testing::TempDir()) {
    overlay_ = dir_ + "fault_to_hold_" + name + ".yaml";
    std::ofstream(overlay_) << "supervisor:\n  auto_arm: true\n  arming_ramp_s: 0.2\n"
                            << overlay_yaml;
    config_ = LoadStackConfig(DefaultConfigPath(), {overlay_});
    if (!controller_overlay_yaml.empty()) {
      controller_overlay_ = dir_ + "fault_to_hold_" + name + "_controller.yaml";
      std::ofstream(controller_overlay_) << controller_overlay_yaml;
    }
    lcm_ = MakeLcm(url_);
    const auto& ch = config_.lcm.channels;
    lcm_->subscribe(ch.sensors, &Bus::OnSensor, &bus)->setQueueCapacity(1000000);
    lcm_->subscribe(ch.command_safe, &Bus::OnSafe, &bus)->setQueueCapacity(1000000);
    lcm_->subscribe(ch.supervisor, &Bus::OnSupervisor, &bus)->setQueueCapacity(100000);
    lcm_->subscribe(ch.health, &Bus::OnHealth, &bus)->setQueueCapacity(100000);
    lcm_->subscribe(ch.operator_command, &Bus::OnOperator, &bus)->setQueueCapacity(100000);
  }

  const StackConfig& config() const { return config_; }
  lcm::LCM* lcm() { return lcm_.get(); }
  const std::string& url() const { return url_; }
  const std::string& overlay() const { return overlay_; }
  const std::string& controller_overlay() const { return controller_overlay_; }

  std::vector<std::string> With(std::vector<std::string> head) const {
    for (const std::string& s : {std::string("--lcm-url"), url_, std::string("--overlay"), overlay_,
                                 std::string("--log-level"), std::string("warn")}) {
      head.push_back(s);
    }
    return head;
  }
  std::unique_ptr<test::ChildProcess> StartController() const {
    std::vector<std::string> argv = With({CONTROLLER_PATH, "--scenario", "paper"});
    if (!controller_overlay_.empty()) {
      argv.push_back("--overlay");
      argv.push_back(controller_overlay_);
    }
    return std::make_unique<test::ChildProcess>(argv);
  }
  std::unique_ptr<test::ChildProcess> StartEstimator() const {
    return std::make_unique<test::ChildProcess>(With({ESTIMATOR_PATH}));
  }
  void Start() {
    safety = std::make_unique<test::ChildProcess>(With({SAFETY_PATH}));
    controller = StartController();
    estimator = StartEstimator();
    plant = std::make_unique<test::ChildProcess>(With({PLANT_SIM_PATH, "--mode", "realtime"}));
  }
  bool Started() const {
    return safety->started() && controller->started() && estimator->started() && plant->started();
  }

  void Pump(double seconds) {
    PumpUntil([] { return false; }, seconds);
  }
  bool PumpUntil(const std::function<bool()>& done, double timeout_s) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
    while (!done()) {
      if (std::chrono::steady_clock::now() > end) return false;
      lcm_->handleTimeout(1);
    }
    return true;
  }

  /// ARMED, the filtered command (no fallback) for the last 300 states,
  /// and a second heartbeat from every process. The supervisor arms by
  /// itself (auto_arm) without asking for heartbeats, within 0.5 s of the
  /// start, before the processes' second heartbeat (1 / rates.health_hz);
  /// a process whose first heartbeat the safety process missed (it was not
  /// listening yet) is never judged silent (ProcessMonitor::CheckSilence
  /// skips processes it has not seen). A stack that runs longer than a
  /// heartbeat period before its fault, as a real one does, is what this
  /// measures.
  bool WaitArmed(double timeout_s) {
    return PumpUntil(
        [&] {
          for (const char* name : {"safety", "estimator", "controller", "plant_sim"}) {
            bool second = false;
            for (const auto& h : bus.health)
              second = second || (h.msg.name == name && h.msg.seq >= 1);
            if (!second) return false;
          }
          if (bus.supervisor.empty() ||
              bus.supervisor.back().msg.state != supervisor_state_t::STATE_ARMED ||
              bus.safe.size() < 300) {
            return false;
          }
          for (size_t i = bus.safe.size() - 300; i < bus.safe.size(); ++i) {
            if (Fallback(bus.safe[i].msg)) return false;
          }
          return true;
        },
        timeout_s);
  }

  /// Measures from a fault at `fault_wall_us` to the first fallback and
  /// the first supervisor state `hold_state` received after it.
  Times Measure(int64_t fault_wall_us, int8_t hold_state) const {
    Times t;
    t.fault_wall_us = fault_wall_us;
    // The first sample after the fault. In real time plant_sim's stack
    // clock is this host's wall clock (its tick schedule, epoch us), so
    // the sample's own time says whether it came after the fault, free of
    // when this test got round to reading it.
    for (const auto& s : bus.sensors) {
      if (s.msg.utime >= fault_wall_us) {
        t.fault_stack_us = s.msg.utime;
        break;
      }
    }
    // The safe stop: the first of the fallbacks that last (to the end of
    // the recording), not one late nominal command on a loaded host.
    for (const auto& c : bus.safe) {
      if (c.recv_us < fault_wall_us) continue;
      if (!Fallback(c.msg)) {
        t.stop_stack_ms.reset();
        t.stop_wall_ms.reset();
      } else if (!t.stop_wall_ms) {
        if (t.fault_stack_us >= 0) {
          t.stop_stack_ms = 1e-3 * double(c.msg.sample_utime - t.fault_stack_us);
        }
        t.stop_wall_ms = 1e-3 * double(c.recv_us - fault_wall_us);
      }
    }
    for (const auto& s : bus.supervisor) {
      if (s.recv_us >= fault_wall_us && s.msg.state == hold_state) {
        if (t.fault_stack_us >= 0) t.hold_stack_ms = 1e-3 * double(s.msg.utime - t.fault_stack_us);
        t.hold_wall_ms = 1e-3 * double(s.recv_us - fault_wall_us);
        t.hold_reason = s.msg.reason;
        break;
      }
    }
    t.lost_sensors = Lost(bus.sensors);
    t.lost_safe = Lost(bus.safe);
    t.lost_supervisor = Lost(bus.supervisor);
    return t;
  }

  /// Runs stewart_ctl `args` while pumping the bus; its exit code.
  int Ctl(const std::vector<std::string>& args, double timeout_s = 5.0) {
    std::vector<std::string> argv = {STEWART_CTL_PATH};
    argv.insert(argv.end(), args.begin(), args.end());
    test::ChildProcess ctl(With(argv));
    if (!ctl.started()) return -1;
    PumpUntil([&] { return !ctl.running(); }, timeout_s);
    return ctl.running() ? -1 : ctl.exit_code();
  }

  Bus bus;
  std::unique_ptr<test::ChildProcess> safety, controller, estimator, plant;

 private:
  std::string url_;
  std::string dir_;
  std::string overlay_;
  std::string controller_overlay_;
  StackConfig config_;
  std::unique_ptr<lcm::LCM> lcm_;
};

void Print(const char* fault, const Times& t, const std::string& extra = "") {
  std::printf(
      "[fault-to-hold] %-22s safe stop %s stack / %s wall; HOLD %s stack / %s wall (%s)%s%s\n",
      fault, Ms(t.stop_stack_ms).c_str(), Ms(t.stop_wall_ms).c_str(), Ms(t.hold_stack_ms).c_str(),
      Ms(t.hold_wall_ms).c_str(), t.hold_reason.c_str(), extra.empty() ? "" : "; ", extra.c_str());
  if (t.lost_sensors + t.lost_safe + t.lost_supervisor > 0) {
    std::printf(
        "[fault-to-hold]   (not received: %lld sensor samples, %lld safe commands, %lld "
        "supervisor states)\n",
        static_cast<long long>(t.lost_sensors), static_cast<long long>(t.lost_safe),
        static_cast<long long>(t.lost_supervisor));
  }
  std::fflush(stdout);
}

// Config-derived bounds. One sensor period of stack time per hop, and a
// stated slack: kStackSlackMs of stack time (a late sample on a shared
// host), kWallSlackMs of wall time (scheduling, process start).
constexpr double kStackSlackMs = 5.0;
constexpr double kWallSlackMs = 150.0;

double PeriodMs(const StackConfig& c) { return 1e3 / c.sensors.rate_hz; }
double WatchdogStopMs(const StackConfig& c) {
  return 1e3 * c.safety.stale_age_s + 2 * PeriodMs(c) + kStackSlackMs;
}
double WatchdogHoldMs(const StackConfig& c) {
  return WatchdogStopMs(c) + 1e3 * c.supervisor.fallback_latch_s;
}

/// The controller's nominal watchdog, then the fallback latch: SIGKILL.
TEST(FaultToHold, ControllerKilled) {
  test::LauncherLock lock;
  Stack stack("controller_killed", kPortBase + 0, "");
  stack.Start();
  ASSERT_TRUE(stack.Started());
  ASSERT_TRUE(stack.WaitArmed(8.0)) << "the stack did not arm";
  const int64_t fault = WallUs();
  stack.controller->Stop(SIGKILL);
  stack.PumpUntil(
      [&] { return stack.Measure(fault, supervisor_state_t::STATE_HOLD).hold_wall_ms.has_value(); },
      2.0);
  stack.Pump(0.1);
  const Times t = stack.Measure(fault, supervisor_state_t::STATE_HOLD);
  const StackConfig& c = stack.config();
  Print("controller killed", t);
  ASSERT_TRUE(t.stop_stack_ms && t.hold_stack_ms);
  EXPECT_LE(*t.stop_stack_ms, WatchdogStopMs(c));
  EXPECT_LE(*t.hold_stack_ms, WatchdogHoldMs(c));
  EXPECT_LE(*t.hold_wall_ms, WatchdogHoldMs(c) + kWallSlackMs);
  EXPECT_NE(t.hold_reason.find("nominal"), std::string::npos) << t.hold_reason;
}

double HeartbeatPeriodMs(const StackConfig& c) { return 1e3 / c.lcm.health_rate_hz; }

/// The first heartbeat of `name` received after `after_us` that `pred` holds for.
const Received<health_t>* FirstBeat(const Bus& bus, const std::string& name, int64_t after_us,
                                    const std::function<bool(const health_t&)>& pred) {
  for (const auto& h : bus.health) {
    if (h.recv_us >= after_us && h.msg.name == name && pred(h.msg)) return &h;
  }
  return nullptr;
}

/// The newest heartbeat of `name` received before `before_us`.
const Received<health_t>* LastBeat(const Bus& bus, const std::string& name, int64_t before_us) {
  const Received<health_t>* last = nullptr;
  for (const auto& h : bus.health) {
    if (h.recv_us < before_us && h.msg.name == name) last = &h;
  }
  return last;
}

/// The estimator dies: no state, so the safety process (which answers
/// states) publishes nothing; plant_sim's command timeout turns the
/// actuators off (its sensor samples say so: STATUS_ACTUATORS_OFF), and
/// HOLD latches when the estimator's heartbeat is lost (wall time).
TEST(FaultToHold, EstimatorKilled) {
  test::LauncherLock lock;
  Stack stack("estimator_killed", kPortBase + 1, "");
  stack.Start();
  ASSERT_TRUE(stack.Started());
  ASSERT_TRUE(stack.WaitArmed(8.0)) << "the stack did not arm";
  const StackConfig& c = stack.config();
  const int64_t fault = WallUs();
  const Received<health_t>* last_beat = LastBeat(stack.bus, "estimator", fault);
  ASSERT_NE(last_beat, nullptr);
  const int64_t last_beat_us = last_beat->recv_us;  // the bus grows: no pointer kept
  stack.estimator->Stop(SIGKILL);
  stack.PumpUntil(
      [&] { return stack.Measure(fault, supervisor_state_t::STATE_HOLD).hold_wall_ms.has_value(); },
      c.supervisor.heartbeat_timeout_s + 1.0);
  stack.Pump(0.1);
  const Times t = stack.Measure(fault, supervisor_state_t::STATE_HOLD);
  size_t commands_after = 0;
  for (const auto& cmd : stack.bus.safe) commands_after += cmd.recv_us > fault + 20'000 ? 1 : 0;
  std::optional<double> off_stack_ms, off_wall_ms;
  for (const auto& smp : stack.bus.sensors) {
    if (smp.recv_us >= fault && (smp.msg.status & sensor_t::STATUS_ACTUATORS_OFF) != 0) {
      off_stack_ms = 1e-3 * double(smp.msg.utime - t.fault_stack_us);
      off_wall_ms = 1e-3 * double(smp.recv_us - fault);
      break;
    }
  }
  char extra[200];
  std::snprintf(extra, sizeof extra,
                "%zu safe commands after kill+20 ms; plant_sim actuators off %s stack / %s wall; "
                "estimator's last heartbeat %.0f ms before the kill",
                commands_after, Ms(off_stack_ms).c_str(), Ms(off_wall_ms).c_str(),
                1e-3 * double(fault - last_beat_us));
  Print("estimator killed", t, extra);
  ASSERT_TRUE(t.hold_wall_ms && off_stack_ms);
  // The silence is judged from its last heartbeat, up to a period before the kill.
  EXPECT_LE(*t.hold_wall_ms, 1e3 * c.supervisor.heartbeat_timeout_s + kWallSlackMs);
  EXPECT_GE(*t.hold_wall_ms, 1e3 * c.supervisor.heartbeat_timeout_s - HeartbeatPeriodMs(c) - 10.0);
  EXPECT_NE(t.hold_reason.find("estimator heartbeat lost"), std::string::npos) << t.hold_reason;
  EXPECT_EQ(commands_after, 0u) << "the safety process answered without states";
  EXPECT_LE(*off_stack_ms, 1e3 * c.plant_sim.command_timeout_s + 2 * PeriodMs(c) + kStackSlackMs);
}

/// The estimator is killed and started again at once: its heartbeat starts
/// over (a restart), its first states are not usable (initialising).
TEST(FaultToHold, EstimatorRestarted) {
  test::LauncherLock lock;
  Stack stack("estimator_restarted", kPortBase + 2, "");
  stack.Start();
  ASSERT_TRUE(stack.Started());
  ASSERT_TRUE(stack.WaitArmed(8.0)) << "the stack did not arm";
  const StackConfig& c = stack.config();
  const int64_t fault = WallUs();
  stack.estimator->Stop(SIGKILL);
  stack.estimator = stack.StartEstimator();
  ASSERT_TRUE(stack.estimator->started());
  stack.PumpUntil(
      [&] {
        const Times t = stack.Measure(fault, supervisor_state_t::STATE_HOLD);
        return t.hold_wall_ms && t.stop_wall_ms;
      },
      c.supervisor.heartbeat_timeout_s + 1.0);
  stack.Pump(0.1);
  const Times t = stack.Measure(fault, supervisor_state_t::STATE_HOLD);
  const Received<health_t>* first_beat =
      FirstBeat(stack.bus, "estimator", fault, [](const health_t&) { return true; });
  int64_t first_state_stack = -1;
  for (const auto& cmd : stack.bus.safe) {
    if (cmd.recv_us > fault + 1000) {
      first_state_stack = cmd.msg.sample_utime;
      break;
    }
  }
  char extra[200];
  std::snprintf(extra, sizeof extra,
                "new estimator's first heartbeat %s wall, first safe command after the restart %s "
                "stack",
                first_beat ? Ms(1e-3 * double(first_beat->recv_us - fault)).c_str() : "never",
                first_state_stack >= 0 && t.fault_stack_us >= 0
                    ? Ms(1e-3 * double(first_state_stack - t.fault_stack_us)).c_str()
                    : "never");
  Print("estimator restarted", t, extra);
  ASSERT_TRUE(t.hold_wall_ms && t.stop_wall_ms);
  // Before its heartbeat could be judged silent: the restart (or its
  // unusable states) latched, within the new process's start-up.
  EXPECT_LT(*t.hold_wall_ms, 1e3 * c.supervisor.heartbeat_timeout_s);
  EXPECT_EQ(t.hold_reason.find("heartbeat lost"), std::string::npos) << t.hold_reason;
}

/// Relays the estimator's states to the controller (on its own channel),
/// from `shift_us` on with their times 2 s in the past: a clock step the
/// controller rejects as implausible, every state, so it reports FAULT.
struct Relay {
  void On(const lcm::ReceiveBuffer*, const std::string&, const state_t* m) {
    state_t s = *m;
    s.utime -= shift_us;
    s.sample_utime -= shift_us;
    lcm->publish(channel, &s);
  }
  lcm::LCM* lcm = nullptr;
  std::string channel;
  int64_t shift_us = 0;
};

/// A required process reports FAULT: the controller, rejecting every state
/// for longer than controller.stale_age_s (as health_ack_test drives it).
/// It publishes no nominal command meanwhile, so the safety process's
/// watchdog runs as well: whichever latches first.
TEST(FaultToHold, ControllerReportsFault) {
  test::LauncherLock lock;
  const std::string controller_overlay = "lcm:\n  channels:\n    state_estimate: STATE_EST_RELAY\n";
  Stack stack("controller_fault", kPortBase + 3, "", controller_overlay);
  Relay relay;
  relay.lcm = stack.lcm();
  relay.channel =
      LoadStackConfig(DefaultConfigPath(), {stack.overlay(), stack.controller_overlay()})
          .lcm.channels.state_estimate;
  ASSERT_NE(relay.channel, stack.config().lcm.channels.state_estimate);
  stack.lcm()->subscribe(stack.config().lcm.channels.state_estimate, &Relay::On, &relay);
  stack.Start();
  ASSERT_TRUE(stack.Started());
  ASSERT_TRUE(stack.WaitArmed(8.0)) << "the stack did not arm";
  const StackConfig& c = stack.config();
  const int64_t fault = WallUs();
  relay.shift_us = 2'000'000;
  const auto is_fault = [](const health_t& h) { return h.state == health_t::STATE_FAULT; };
  stack.PumpUntil(
      [&] {
        return stack.Measure(fault, supervisor_state_t::STATE_HOLD).hold_wall_ms.has_value() &&
               FirstBeat(stack.bus, "controller", fault, is_fault) != nullptr;
      },
      3.0);
  stack.Pump(0.1);
  const Times t = stack.Measure(fault, supervisor_state_t::STATE_HOLD);
  const Received<health_t>* beat = FirstBeat(stack.bus, "controller", fault, is_fault);
  char extra[200];
  std::snprintf(extra, sizeof extra, "controller's FAULT heartbeat %s wall (%s)",
                beat ? Ms(1e-3 * double(beat->recv_us - fault)).c_str() : "never",
                beat ? beat->msg.latched_error.substr(0, 60).c_str() : "");
  Print("controller FAULT", t, extra);
  ASSERT_TRUE(t.stop_stack_ms && t.hold_stack_ms && t.hold_wall_ms);
  ASSERT_NE(beat, nullptr) << "the controller never reported FAULT";
  EXPECT_LE(*t.stop_stack_ms, WatchdogStopMs(c));
  EXPECT_LE(*t.hold_stack_ms, WatchdogHoldMs(c));
  EXPECT_LE(1e-3 * double(beat->recv_us - fault),
            1e3 * c.controller.stale_age_s + HeartbeatPeriodMs(c) + kWallSlackMs);
}

/// A required process goes silent: SIGSTOP the controller. Its nominal
/// commands stop at once (the watchdog), its heartbeat after
/// heartbeat_timeout_s of wall time: both measured.
TEST(FaultToHold, ControllerSilent) {
  test::LauncherLock lock;
  Stack stack("controller_silent", kPortBase + 4, "");
  stack.Start();
  ASSERT_TRUE(stack.Started());
  ASSERT_TRUE(stack.WaitArmed(8.0)) << "the stack did not arm";
  const StackConfig& c = stack.config();
  const int64_t fault = WallUs();
  const Received<health_t>* safety_before = LastBeat(stack.bus, "safety", fault);
  ASSERT_NE(safety_before, nullptr);
  const int64_t faults_before = test::HealthCounter(safety_before->msg, "supervisor_faults");
  stack.controller->Signal(SIGSTOP);
  const auto counted = [&](const health_t& h) {
    return test::HealthCounter(h, "supervisor_faults") > faults_before;
  };
  stack.PumpUntil(
      [&] {
        return stack.Measure(fault, supervisor_state_t::STATE_HOLD).hold_wall_ms.has_value() &&
               FirstBeat(stack.bus, "safety", fault, counted) != nullptr;
      },
      c.supervisor.heartbeat_timeout_s + 2e-3 * HeartbeatPeriodMs(c) + 1.0);
  stack.controller->Signal(SIGCONT);  // so that SIGTERM ends it at the end
  const Received<health_t>* detected = FirstBeat(stack.bus, "safety", fault, counted);
  const Times t = stack.Measure(fault, supervisor_state_t::STATE_HOLD);
  const int64_t detected_us = detected ? detected->recv_us : 0;
  // Its last heartbeat (one may leave between the clock read and the stop).
  const Received<health_t>* last_beat = LastBeat(stack.bus, "controller", WallUs());
  ASSERT_NE(last_beat, nullptr);
  const int64_t last_beat_us = last_beat->recv_us;
  char extra[240];
  std::snprintf(
      extra, sizeof extra,
      "heartbeat loss counted in the safety's heartbeat %s wall after the stop (controller's "
      "last heartbeat %+.0f ms from it; heartbeat_timeout_s %.1f s)",
      detected ? Ms(1e-3 * double(detected_us - fault)).c_str() : "never",
      1e-3 * double(last_beat_us - fault), c.supervisor.heartbeat_timeout_s);
  Print("controller silent", t, extra);
  ASSERT_TRUE(t.stop_stack_ms && t.hold_stack_ms);
  EXPECT_LE(*t.stop_stack_ms, WatchdogStopMs(c));
  EXPECT_LE(*t.hold_stack_ms, WatchdogHoldMs(c));
  EXPECT_NE(t.hold_reason.find("nominal"), std::string::npos)
      << "the watchdog did not fire first: " << t.hold_reason;
  ASSERT_NE(detected, nullptr) << "the silence was never counted as a fault";
  // Judged from the last heartbeat; seen at the safety's next heartbeat.
  const double detected_after_beat_ms = 1e-3 * double(detected_us - last_beat_us);
  // (less 50 ms: both are this test's receive times, read when it runs)
  EXPECT_GE(detected_after_beat_ms, 1e3 * c.supervisor.heartbeat_timeout_s - 50.0);
  EXPECT_LE(detected_after_beat_ms,
            1e3 * c.supervisor.heartbeat_timeout_s + HeartbeatPeriodMs(c) + kWallSlackMs);
}

/// The operator's commands, from stewart_ctl: measured from the command's
/// utime (when the console sent it).
void OperatorCommand(const char* name, int port, const char* verb, int8_t command, int8_t state) {
  test::LauncherLock lock;
  Stack stack(std::string("operator_") + verb, port, "");
  stack.Start();
  ASSERT_TRUE(stack.Started());
  ASSERT_TRUE(stack.WaitArmed(8.0)) << "the stack did not arm";
  const StackConfig& c = stack.config();
  const int64_t started = WallUs();
  EXPECT_EQ(stack.Ctl({verb}), 0);
  const double ctl_ms = 1e-3 * double(WallUs() - started);
  int64_t fault = -1;
  const auto find_command = [&] {
    for (const auto& op : stack.bus.operators) {
      if (op.msg.command == command) {
        // Its send time (the console's clock, this host's): the safety
        // process can receive it, act and announce a few us before the
        // test's own copy is timestamped.
        fault = op.msg.utime;
        return true;
      }
    }
    return false;
  };
  // stewart_ctl can exit before this process has read its command from the
  // socket (a loaded machine schedules the test late): read on until it is.
  stack.PumpUntil(find_command, 1.0);
  ASSERT_GT(fault, 0) << "no " << verb << " on the operator channel";
  stack.PumpUntil([&] { return stack.Measure(fault, state).hold_wall_ms.has_value(); }, 1.0);
  stack.Pump(0.1);
  const Times t = stack.Measure(fault, state);
  char extra[120];
  std::snprintf(extra, sizeof extra, "stewart_ctl %s returned after %.0f ms", verb, ctl_ms);
  Print(name, t, extra);
  ASSERT_TRUE(t.stop_stack_ms && t.hold_wall_ms);
  EXPECT_LE(*t.stop_stack_ms, 2 * PeriodMs(c) + kStackSlackMs);
  EXPECT_LE(*t.hold_wall_ms, kWallSlackMs);
}

TEST(FaultToHold, OperatorHold) {
  OperatorCommand("operator hold", kPortBase + 5, "hold", operator_command_t::COMMAND_HOLD,
                  supervisor_state_t::STATE_HOLD);
}

TEST(FaultToHold, OperatorEstop) {
  OperatorCommand("operator estop", kPortBase + 6, "estop", operator_command_t::COMMAND_ESTOP,
                  supervisor_state_t::STATE_ESTOP);
}

/// The dead-man (supervisor.operator_timeout_s 0.5 s): the console's
/// heartbeats stop (SIGKILL).
TEST(FaultToHold, OperatorDeadMan) {
  test::LauncherLock lock;
  Stack stack("deadman", kPortBase + 7, "  operator_timeout_s: 0.5\n");
  // The console first: the dead-man counts from the safety process's start.
  test::ChildProcess console(stack.With({STEWART_CTL_PATH, "heartbeat", "--period", "0.1"}));
  stack.Pump(0.3);
  stack.Start();
  ASSERT_TRUE(stack.Started() && console.started());
  ASSERT_TRUE(stack.WaitArmed(8.0)) << "the stack did not arm";
  const StackConfig& c = stack.config();
  const int64_t fault = WallUs();
  console.Stop(SIGKILL);
  stack.PumpUntil(
      [&] { return stack.Measure(fault, supervisor_state_t::STATE_HOLD).hold_wall_ms.has_value(); },
      c.supervisor.operator_timeout_s + 1.0);
  stack.Pump(0.1);
  const Times t = stack.Measure(fault, supervisor_state_t::STATE_HOLD);
  int64_t last_heartbeat = -1;
  for (const auto& op : stack.bus.operators) {
    if (op.msg.command == operator_command_t::COMMAND_HEARTBEAT && op.msg.utime < fault) {
      last_heartbeat = op.msg.utime;  // sent (the console's clock, this host's)
    }
  }
  ASSERT_GT(last_heartbeat, 0);
  const Times from_beat = stack.Measure(last_heartbeat, supervisor_state_t::STATE_HOLD);
  char extra[120];
  std::snprintf(extra, sizeof extra, "from the last operator heartbeat: HOLD %s wall",
                Ms(from_beat.hold_wall_ms).c_str());
  Print("dead-man", t, extra);
  ASSERT_TRUE(t.hold_wall_ms && from_beat.hold_wall_ms && t.stop_stack_ms);
  EXPECT_GE(*from_beat.hold_wall_ms, 1e3 * c.supervisor.operator_timeout_s);
  EXPECT_LE(*from_beat.hold_wall_ms, 1e3 * c.supervisor.operator_timeout_s + kWallSlackMs);
  EXPECT_NE(t.hold_reason.find("dead-man"), std::string::npos) << t.hold_reason;
}

}  // namespace
}  // namespace stewart
