// Process faults on a running real-time stack: each of plant_sim, estimator,
// controller, safety, stewart_logger and (hardware mode) hw_emulator and
// hw_bridge is stopped (SIGSTOP, then
// SIGCONT) and killed (SIGKILL, then started again) at a random instant
// once the supervisor is ARMED (seeded: the seed is printed, and
// STEWART_FAULT_SEED=N repeats it). The real processes on a private URL
// (plant_sim in real time at 1 kHz, or hw_bridge against hw_emulator;
// estimator, controller, safety, stewart_logger), armed by the supervisor at
// start-up as tools/launch.sh does in simulation. For every fault:
//
// plant_sim and hw_emulator are not the model: --truth
// test::WriteMismatchedTruth (heavier, a payload, joint errors, friction,
// force-gain errors, a constant push), so the claims below hold against
// physics the stack does not know exactly.
//
//   - no surviving process dies;
//   - every limit holds on ground truth (STATE_TRUE, from plant_sim or the
//     emulator), heard on the bus by the test;
//   - the stack reaches its safe state (the actuators off on the plant's
//     command timeout, the safety process's fallback, the supervisor's
//     HOLD), timed from the fault: one "[process-fault] <process> <kill|stop>"
//     line each (docs/operations.md, "Process faults");
//   - it recovers, but the supervisor moves again only after an operator's
//     stewart_ctl reset and resume (arm for a new safety process), never by
//     itself;
//   - the rejections are counted where they land (health_t counters).
//
// stewart_logger: killed and restarted (appending to its log), the stack is
// unaffected and stewart_log_export --check names the gap; stopped for
// 0.5 s, what it loses is counted by the same check.
//
// STEWART_SOAK_S=S repeats the faults of each test at random instants for S
// seconds of wall time (default 0: once each, the CI's short profile).
//
// LCM ports 8020-8026 (this file owns 8020-8029), device UDP ports 8028
// (hw_emulator) and 8029 (hw_bridge). Each test holds the build folder's
// launcher lock: a real-time stack alone on the shared cores.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "stewart/config/config_loader.h"
#include "stewart/force_command_t.hpp"
#include "stewart/health_t.hpp"
#include "stewart/node/lcm_handle.h"
#include "stewart/sensor_t.hpp"
#include "stewart/state_t.hpp"
#include "stewart/supervisor_state_t.hpp"
#include "stewart/test_support/child_process.h"
#include "stewart/test_support/health_counter.h"
#include "stewart/test_support/recorded_run.h"
#include "stewart/test_support/stack_launch.h"

namespace stewart {
namespace {

constexpr int kPortPlantSim = 8020;
constexpr int kPortSafety = 8021;
constexpr int kPortLogger = 8022;
constexpr int kPortHwEmulator = 8023;
constexpr int kPortHwBridge = 8024;
constexpr int kPortEstimator = 8025;
constexpr int kPortController = 8026;
constexpr int kDevicePort = 8028;  // hw_bridge binds kDevicePort + 1

int64_t WallUs() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

bool Fallback(const force_command_t& c) { return (c.flags & force_command_t::FLAG_FALLBACK) != 0; }

template <typename Msg>
struct Received {
  Msg msg;
  int64_t recv_us;  // wall time the test received it
};

/// The seed of this run's fault instants: STEWART_FAULT_SEED, else the clock.
uint64_t Seed() {
  static const uint64_t seed = [] {
    const char* env = std::getenv("STEWART_FAULT_SEED");
    return env != nullptr ? std::strtoull(env, nullptr, 10)
                          : static_cast<uint64_t>(WallUs() % 1'000'000'007);
  }();
  return seed;
}

/// STEWART_SOAK_S: seconds to repeat each test's faults for (0: once).
double SoakSeconds() {
  const char* env = std::getenv("STEWART_SOAK_S");
  return env != nullptr ? std::strtod(env, nullptr) : 0.0;
}

std::string Ms(const std::optional<double>& v) {
  if (!v) return "never";
  char s[32];
  std::snprintf(s, sizeof s, "%.1f ms", *v);
  return s;
}

/// What the test hears of the stack, with receive times; ground truth is
/// checked against the limits as it comes.
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
  void OnTruth(const lcm::ReceiveBuffer*, const std::string&, const state_t* m) {
    test::AddTruthSample(*m, &truth);
    last_truth = *m;
  }
  std::vector<Received<sensor_t>> sensors;
  std::vector<Received<force_command_t>> safe;
  std::vector<Received<supervisor_state_t>> supervisor;
  std::vector<Received<health_t>> health;
  test::RecordedRun truth;
  state_t last_truth{};
};

/// The stack's processes on a private URL, and the test's ear on it.
class Stack {
 public:
  Stack(const std::string& name, int port, bool hardware)
      : hardware_(hardware), url_(PrivateLcmUrl(port)) {
    std::string pattern = "/tmp/stewart_process_faults_" + name + "_XXXXXX";
    if (mkdtemp(pattern.data()) != nullptr) folder_ = pattern;
    log_path_ = folder_ + "/log.lcm";
    // After the overlay's "supervisor:" (auto_arm): a short ramp, the device's ports.
    std::string extra = "  arming_ramp_s: 0.2\n";
    if (hardware_) {
      extra += "hw_bridge:\n  device_port: " + std::to_string(kDevicePort) +
               "\n  local_port: " + std::to_string(kDevicePort + 1) + "\n";
    }
    overlay_ = test::WriteAutoArmOverlay(folder_, extra);
    truth_ = test::WriteMismatchedTruth(folder_);
    manual_arm_overlay_ = folder_ + "/manual_arm.yaml";
    std::ofstream(manual_arm_overlay_) << "supervisor:\n  auto_arm: false\n";
    config_ = LoadStackConfig(DefaultConfigPath(), {overlay_});
    bus.truth.bounds = test::BoundsOf(config_.safety);
    lcm_ = MakeLcm(url_);
    const auto& ch = config_.lcm.channels;
    lcm_->subscribe(ch.sensors, &Bus::OnSensor, &bus)->setQueueCapacity(1000000);
    lcm_->subscribe(ch.command_safe, &Bus::OnSafe, &bus)->setQueueCapacity(1000000);
    lcm_->subscribe(ch.supervisor, &Bus::OnSupervisor, &bus)->setQueueCapacity(100000);
    lcm_->subscribe(ch.health, &Bus::OnHealth, &bus)->setQueueCapacity(100000);
    lcm_->subscribe(ch.state_truth, &Bus::OnTruth, &bus)->setQueueCapacity(1000000);
  }
  ~Stack() {
    // Survivors first, the logger last: it records their last heartbeats.
    for (auto* p : {&plant, &bridge, &emulator, &estimator, &controller, &safety, &logger}) {
      p->reset();
    }
    if (!folder_.empty() && !::testing::Test::HasFailure()) {
      std::error_code ignored;
      std::filesystem::remove_all(folder_, ignored);
    } else if (!folder_.empty()) {
      std::printf("run folder kept: %s\n", folder_.c_str());
    }
  }

  const StackConfig& config() const { return config_; }
  const std::string& log_path() const { return log_path_; }
  const std::string& folder() const { return folder_; }
  bool hardware() const { return hardware_; }
  /// The process a plant fault hits first: plant_sim or hw_bridge.
  const char* plant_name() const { return hardware_ ? "hw_bridge" : "plant_sim"; }

  std::vector<std::string> With(std::vector<std::string> head) const {
    return test::WithStackFlags(std::move(head), url_, overlay_);
  }
  /// The logger on the stack's URL; `append` continues the log (a restart).
  std::unique_ptr<test::ChildProcess> StartLogger(bool append) const {
    // 32 MB: a stopped process that resumes replays its backlog as a burst of
    // thousands of messages; 4 MB overflowed once under CI load (4 samples).
    std::vector<std::string> argv = {LOGGER_PATH, "--lcm-url=" + url_ + "&recv_buf_size=33554432"};
    argv.push_back(append ? "--append" : "-f");
    argv.push_back(log_path_);
    return std::make_unique<test::ChildProcess>(argv);
  }
  /// `auto_arm` false: as on hardware, where the supervisor never arms by
  /// itself (an operator restarting it after a fault).
  std::unique_ptr<test::ChildProcess> StartSafety(bool auto_arm = true) const {
    std::vector<std::string> argv = With({SAFETY_PATH});
    if (!auto_arm) {
      argv.push_back("--overlay");
      argv.push_back(manual_arm_overlay_);
    }
    return std::make_unique<test::ChildProcess>(argv);
  }
  std::unique_ptr<test::ChildProcess> StartPlantSim() const {
    return std::make_unique<test::ChildProcess>(
        With({PLANT_SIM_PATH, "--mode", "realtime", "--truth", truth_}));
  }
  std::unique_ptr<test::ChildProcess> StartEmulator() const {
    return std::make_unique<test::ChildProcess>(With({HW_EMULATOR_PATH, "--truth", truth_}));
  }
  std::unique_ptr<test::ChildProcess> StartBridge() const {
    return std::make_unique<test::ChildProcess>(With({HW_BRIDGE_PATH}));
  }
  std::unique_ptr<test::ChildProcess> StartController() const {
    return std::make_unique<test::ChildProcess>(With({CONTROLLER_PATH, "--scenario", "paper"}));
  }
  std::unique_ptr<test::ChildProcess> StartEstimator() const {
    return std::make_unique<test::ChildProcess>(With({ESTIMATOR_PATH}));
  }
  void Start() {
    // The logger first, and recording before anything publishes: it creates
    // its log right after joining the group and subscribes right after
    // that. Started together, plant_sim's first samples went out before the
    // logger subscribed on a loaded host (a CI run's log began at sensor
    // seq 7: a gap no fault explains).
    logger = StartLogger(false);
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (!std::filesystem::exists(log_path_) && std::chrono::steady_clock::now() < deadline) {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));  // its subscription, after the file
    safety = StartSafety();
    controller = StartController();
    estimator = StartEstimator();
    if (hardware_) {
      emulator = StartEmulator();
      bridge = StartBridge();
    } else {
      plant = StartPlantSim();
    }
  }
  /// Every process of the stack that runs now, with its name.
  std::vector<std::pair<std::string, test::ChildProcess*>> Processes() {
    std::vector<std::pair<std::string, test::ChildProcess*>> all;
    for (auto& [name, p] :
         std::vector<std::pair<std::string, std::unique_ptr<test::ChildProcess>*>>{
             {"stewart_logger", &logger},
             {"safety", &safety},
             {"controller", &controller},
             {"estimator", &estimator},
             {"plant_sim", &plant},
             {"hw_bridge", &bridge},
             {"hw_emulator", &emulator}}) {
      if (*p) all.emplace_back(name, p->get());
    }
    return all;
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

  /// ARMED, the last 300 safe commands filtered (no fallback), and a second
  /// heartbeat from every required process since `since_us` (as
  /// FaultToHold waits: a process the safety process has heard from).
  bool WaitArmed(double timeout_s, int64_t since_us = 0) {
    const std::vector<std::string> required = {"safety", "estimator", "controller", plant_name()};
    return PumpUntil(
        [&] {
          for (const std::string& name : required) {
            int beats = 0;
            for (const auto& h : bus.health) {
              beats += h.recv_us >= since_us && h.msg.name == name ? 1 : 0;
            }
            if (beats < 2) return false;
          }
          if (bus.supervisor.empty() ||
              bus.supervisor.back().msg.state != supervisor_state_t::STATE_ARMED ||
              bus.safe.size() < 300) {
            return false;
          }
          for (size_t i = bus.safe.size() - 300; i < bus.safe.size(); ++i) {
            if (Fallback(bus.safe[i].msg) || bus.safe[i].recv_us < since_us) return false;
          }
          return true;
        },
        timeout_s);
  }

  /// Runs stewart_ctl `verb` while pumping the bus; its exit code (5:
  /// refused, its reason on stderr).
  int Ctl(const std::string& verb, double timeout_s = 5.0) {
    test::ChildProcess ctl(With({STEWART_CTL_PATH, verb}));
    if (!ctl.started()) return -1;
    PumpUntil([&] { return !ctl.running(); }, timeout_s);
    return ctl.running() ? -1 : ctl.exit_code();
  }

  /// Whether the stack moved again by itself from `from_us` on: a
  /// supervisor state ARMING (a transition into motion), or a safe command
  /// that is neither the safe stop (FLAG_FALLBACK) nor drive-off. What moved,
  /// or "" when nothing did.
  std::string MovedSince(int64_t from_us) const {
    for (const auto& s : bus.supervisor) {
      if (s.recv_us >= from_us && s.msg.state == supervisor_state_t::STATE_ARMING) {
        return "supervisor ARMING (" + s.msg.reason + ")";
      }
    }
    for (const auto& c : bus.safe) {
      if (c.recv_us >= from_us && !Fallback(c.msg) &&
          (c.msg.flags & force_command_t::FLAG_DRIVE_OFF) == 0) {
        return "a filtered safe command, sample " + std::to_string(c.msg.sample_utime) + ", " +
               std::to_string(c.recv_us - from_us) + " us after the stack held";
      }
    }
    return "";
  }

  Bus bus;
  std::unique_ptr<test::ChildProcess> logger, safety, controller, estimator, plant, bridge,
      emulator;

 private:
  bool hardware_;
  std::string url_;
  std::string folder_;
  std::string log_path_;
  std::string overlay_;
  std::string manual_arm_overlay_;
  std::string truth_;  // plant_sim's physics: not the model (test::WriteMismatchedTruth)
  StackConfig config_;
  std::unique_ptr<lcm::LCM> lcm_;
};

/// The times from one fault to the stack's safe states (ms of wall time
/// from the fault; nullopt: never seen).
struct SafeTimes {
  std::optional<double> actuators_off_ms;  // the first sensor sample flagged ACTUATORS_OFF
  std::optional<double> fallback_ms;       // the first of the lasting CMD_SAFE fallbacks
  std::optional<double> hold_ms;           // the first supervisor_state_t in HOLD
  std::string hold_reason;
  std::optional<double> sensors_stop_ms;  // the last sensor sample before a silence (> 20 ms)
};

SafeTimes Measure(const Bus& bus, int64_t fault_us, int64_t until_us) {
  SafeTimes t;
  for (const auto& s : bus.sensors) {
    if (s.recv_us >= fault_us && s.recv_us <= until_us &&
        (s.msg.status & sensor_t::STATUS_ACTUATORS_OFF) != 0) {
      t.actuators_off_ms = 1e-3 * double(s.recv_us - fault_us);
      break;
    }
  }
  for (const auto& c : bus.safe) {
    if (c.recv_us < fault_us || c.recv_us > until_us) continue;
    if (!Fallback(c.msg)) {
      t.fallback_ms.reset();
    } else if (!t.fallback_ms) {
      t.fallback_ms = 1e-3 * double(c.recv_us - fault_us);
    }
  }
  for (const auto& s : bus.supervisor) {
    if (s.recv_us >= fault_us && s.recv_us <= until_us &&
        s.msg.state == supervisor_state_t::STATE_HOLD) {
      t.hold_ms = 1e-3 * double(s.recv_us - fault_us);
      t.hold_reason = s.msg.reason;
      break;
    }
  }
  return t;
}

/// Counters of every process's heartbeats around a fault: `name` -> the last
/// heartbeat before and the last one received by `after_us`.
struct CounterDelta {
  std::map<std::string, health_t> before, after;
  int64_t Rejected(const std::string& name) const {
    const auto b = before.find(name), a = after.find(name);
    if (a == after.end()) return 0;
    // A restarted process counts from zero.
    const int64_t base = b != before.end() && a->second.messages_in >= b->second.messages_in
                             ? b->second.rejected_inputs
                             : 0;
    return a->second.rejected_inputs - base;
  }
  int64_t Of(const std::string& name, const std::string& counter) const {
    const auto b = before.find(name), a = after.find(name);
    if (a == after.end()) return 0;
    const int64_t base = b != before.end() && a->second.messages_in >= b->second.messages_in
                             ? test::HealthCounter(b->second, counter)
                             : 0;
    return test::HealthCounter(a->second, counter) - base;
  }
};

CounterDelta Counters(const Bus& bus, int64_t fault_us, int64_t after_us) {
  CounterDelta d;
  for (const auto& h : bus.health) {
    if (h.recv_us < fault_us) d.before[h.msg.name] = h.msg;
    if (h.recv_us <= after_us) d.after[h.msg.name] = h.msg;
  }
  return d;
}

std::string RejectionsLine(const CounterDelta& d) {
  std::string line;
  for (const auto& [name, h] : d.after) {
    const int64_t r = d.Rejected(name);
    if (r == 0) continue;
    line += (line.empty() ? "" : ", ") + name + " +" + std::to_string(r) + " (" +
            h.last_error.substr(0, 70) + ")";
  }
  return line.empty() ? "none" : line;
}

/// A random instant: up to a heartbeat period and a bit after `now`, so the
/// fault falls at any phase of the heartbeats and ticks.
double RandomDelayS(std::mt19937_64* rng, const StackConfig& config) {
  return std::uniform_real_distribution<double>(0.0, 1.0 / config.lcm.health_rate_hz + 0.2)(*rng);
}

void ExpectAllRunning(Stack& stack, const std::string& except, const std::string& when) {
  for (auto& [name, p] : stack.Processes()) {
    if (name == except) continue;
    EXPECT_TRUE(p->running()) << name << " died (exit code " << p->exit_code() << ") " << when;
  }
}

/// One fault: when it hit, when the process came back, what was measured.
struct FaultRun {
  int64_t fault_us = 0;
  int64_t resumed_us = 0;  // SIGCONT sent, or the new process started
  int64_t safe_us = 0;     // the stack held: the first of HOLD and the actuators off
  SafeTimes times;
};

/// After a fault: from `safe_us` (the stack held) the supervisor does not
/// move by itself for `quiet_s` after `resumed_us` (restart, SIGCONT), then
/// the operator acknowledges (reset) and resumes (or arms, `verb`) until the
/// supervisor accepts (the estimator may need to converge first); ARMED
/// again and the platform moves. Returns the wall time of the operator's
/// accepted command (0: never).
int64_t ExpectOperatorRecovery(Stack& stack, const FaultRun& run, const std::string& verb,
                               double quiet_s, const std::string& what) {
  const int64_t fault_us = run.fault_us;
  stack.PumpUntil([] { return false; },
                  std::max(0.0, quiet_s - 1e-6 * double(WallUs() - run.resumed_us)));
  const std::string moved = stack.MovedSince(run.safe_us);
  EXPECT_EQ(moved, "") << what << ": the stack moved by itself";
  EXPECT_EQ(stack.Ctl("reset"), 0) << what;
  int64_t accepted_us = 0;
  int refused = 0;
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(8);
  while (std::chrono::steady_clock::now() < end) {
    const int64_t sent = WallUs();
    const int code = stack.Ctl(verb);
    if (code == 0) {
      accepted_us = sent;
      break;
    }
    ++refused;
    stack.Pump(0.3);
  }
  EXPECT_NE(accepted_us, 0) << what << ": " << verb << " refused " << refused << " times";
  if (accepted_us == 0) return 0;
  EXPECT_TRUE(stack.PumpUntil(
      [&] {
        return !stack.bus.supervisor.empty() &&
               stack.bus.supervisor.back().msg.state == supervisor_state_t::STATE_ARMED;
      },
      3.0))
      << what << ": not ARMED after " << verb;
  const double x0 = stack.bus.last_truth.q[0], z0 = stack.bus.last_truth.q[2];
  EXPECT_TRUE(stack.PumpUntil(
      [&] {
        const state_t& s = stack.bus.last_truth;
        return std::abs(s.q[0] - x0) + std::abs(s.q[2] - z0) > 2e-3;
      },
      4.0))
      << what << ": the platform did not move on after " << verb;
  std::printf("[process-fault]   %s: %s accepted after %d refusal(s), %.1f s after the fault\n",
              what.c_str(), verb.c_str(), refused, 1e-6 * double(accepted_us - fault_us));
  return accepted_us;
}

void PrintSeed() {
  std::printf("[process-fault] seed %llu (STEWART_FAULT_SEED=%llu repeats it)\n",
              static_cast<unsigned long long>(Seed()), static_cast<unsigned long long>(Seed()));
  std::fflush(stdout);
}

/// How long a stopped process stays stopped: past the supervisor's
/// heartbeat timeout, so that the silence itself is judged.
double StopSeconds(const StackConfig& c) { return c.supervisor.heartbeat_timeout_s + 0.5; }

/// One fault of `name` (`*target`): SIGSTOP for `stop_s` then SIGCONT, or
/// SIGKILL then `restart()` at once. Waits until `safe(SafeTimes)` or
/// `timeout_s`; prints the "[process-fault]" line; returns the fault's wall
/// time and what was measured.

FaultRun InjectFault(Stack& stack, std::mt19937_64* rng, const std::string& name,
                     std::unique_ptr<test::ChildProcess>* target, bool kill, double stop_s,
                     const std::function<std::unique_ptr<test::ChildProcess>()>& restart,
                     const std::function<bool(const SafeTimes&)>& safe, double timeout_s) {
  const double delay_s = RandomDelayS(rng, stack.config());
  stack.Pump(delay_s);
  FaultRun run;
  run.fault_us = WallUs();
  if (kill) {
    const int code = (*target)->Stop(SIGKILL);
    EXPECT_EQ(code, 128 + SIGKILL) << name;
    *target = restart();
    EXPECT_TRUE((*target)->started()) << name;
    run.resumed_us = WallUs();
  } else {
    (*target)->Signal(SIGSTOP);
    stack.Pump(stop_s);
    (*target)->Signal(SIGCONT);
    run.resumed_us = WallUs();
  }
  stack.PumpUntil([&] { return safe(Measure(stack.bus, run.fault_us, WallUs())); },
                  std::max(0.0, timeout_s - 1e-6 * double(WallUs() - run.fault_us)));
  stack.Pump(0.1);
  run.times = Measure(stack.bus, run.fault_us, WallUs());
  const SafeTimes& t = run.times;
  const std::optional<double> safe_ms = t.hold_ms && t.actuators_off_ms
                                            ? std::min(*t.hold_ms, *t.actuators_off_ms)
                                            : (t.hold_ms ? t.hold_ms : t.actuators_off_ms);
  run.safe_us = run.fault_us + (safe_ms ? std::llround(*safe_ms * 1e3) : 0);
  std::printf(
      "[process-fault] %s %s: actuators off %s, safety fallback %s, HOLD %s (%s); %s %.1f ms "
      "after the fault, at %.3f s after it\n",
      name.c_str(), kill ? "kill" : "stop", Ms(t.actuators_off_ms).c_str(),
      Ms(t.fallback_ms).c_str(), Ms(t.hold_ms).c_str(), t.hold_reason.c_str(),
      kill ? "restarted" : "SIGCONT", 1e-3 * double(run.resumed_us - run.fault_us), delay_s);
  std::fflush(stdout);
  return run;
}

void PrintCounters(const std::string& what, const CounterDelta& d) {
  std::printf("[process-fault]   %s: rejected inputs: %s\n", what.c_str(),
              RejectionsLine(d).c_str());
  std::fflush(stdout);
}

bool SoakGoesOn(const std::chrono::steady_clock::time_point& started, int* rounds) {
  ++*rounds;
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count() <
         SoakSeconds();
}

/// The recorder lost nothing the test heard since it recorded: every sensor
/// sample (utime, seq) heard on the bus from the log's first one on is in
/// the log. (The processes start together: on a loaded host plant_sim's
/// first samples can go out before the logger has subscribed, which is its
/// start, not a loss.) Stops the logger.
void ExpectTheLogHasEverySampleHeard(Stack& stack) {
  ASSERT_EQ(stack.logger->Stop(SIGTERM), 0);
  std::set<std::pair<int64_t, int64_t>> logged;
  lcm::LogFile log(stack.log_path(), "r");
  ASSERT_TRUE(log.good());
  while (const lcm::LogEvent* event = log.readNextEvent()) {
    if (event->channel != stack.config().lcm.channels.sensors) continue;
    sensor_t s;
    if (s.decode(event->data, 0, event->datalen) >= 0) logged.emplace(s.utime, s.seq);
  }
  ASSERT_FALSE(logged.empty()) << "no sensor sample in the log";
  long before_start = 0, missing = 0;
  bool recording = false;  // from the first sample heard that is in the log
  std::string missing_utimes;
  for (const auto& s : stack.bus.sensors) {
    const bool in_log = logged.count({s.msg.utime, s.msg.seq}) > 0;
    recording = recording || in_log;
    if (!recording) {
      ++before_start;
    } else if (!in_log) {
      ++missing;
      if (missing <= 10) missing_utimes += " " + std::to_string(s.msg.utime);
    }
  }
  std::printf(
      "[process-fault] recorder: %zu sensor samples heard, %ld before its first, %ld of the rest "
      "not in the log\n",
      stack.bus.sensors.size(), before_start, missing);
  std::fflush(stdout);
  EXPECT_EQ(missing, 0) << "the recorder lost sensor samples the test heard, utime"
                        << missing_utimes;
  // The logger starts with the stack: at most its start-up's worth before it.
  EXPECT_LT(before_start, 1000) << "the log starts late";
}

/// The rounds of faults of a process whose loss the supervisor holds on:
/// `name` (`*target`) stopped, then killed and `restart`ed, at random
/// instants (again and again for STEWART_SOAK_S). Each fault is held
/// (`check_hold(kill, times)` judges how fast), recovered only by the
/// operator's reset and resume, counted as a supervisor fault, and no other
/// process dies; at the end every limit held on ground truth and the log
/// holds every sample heard.
void HeldFaultRounds(Stack& stack, std::mt19937_64* rng, const std::string& name,
                     std::unique_ptr<test::ChildProcess>* target,
                     const std::function<std::unique_ptr<test::ChildProcess>()>& restart,
                     const std::function<void(bool kill, const SafeTimes&)>& check_hold) {
  const StackConfig& c = stack.config();
  const auto started = std::chrono::steady_clock::now();
  int rounds = 0;
  do {
    for (const bool kill : {false, true}) {
      const std::string what = name + (kill ? " kill" : " stop");
      const FaultRun run = InjectFault(
          stack, rng, name, target, kill, StopSeconds(c), restart,
          [](const SafeTimes& t) { return t.hold_ms.has_value(); }, StopSeconds(c) + 2.0);
      ASSERT_TRUE(run.times.hold_ms) << what << ": never held";
      check_hold(kill, run.times);
      ExpectOperatorRecovery(stack, run, "resume", 1.0, what);
      const CounterDelta d = Counters(stack.bus, run.fault_us, WallUs());
      PrintCounters(what, d);
      EXPECT_GT(d.Of("safety", "supervisor_faults"), 0) << what;
      ExpectAllRunning(stack, "", "after " + what);
      ASSERT_TRUE(stack.WaitArmed(5.0, WallUs() - 1'000'000)) << what << ": not back to normal";
    }
  } while (SoakGoesOn(started, &rounds));
  std::printf("[process-fault] %s: %d round(s); %s\n", name.c_str(), rounds,
              test::Describe(stack.bus.truth).c_str());
  test::ExpectWithinLimits(stack.bus.truth);
  ExpectTheLogHasEverySampleHeard(stack);
}

// The plant dies or stops: no sensor sample, so no state and no command;
// the supervisor holds when plant_sim's heartbeat is lost
// (supervisor.heartbeat_timeout_s) or restarts (its sequence starts over).
TEST(ProcessFaults, PlantSimStoppedAndKilled) {
  test::LauncherLock lock;
  PrintSeed();
  std::mt19937_64 rng(Seed() * 4 + 0);
  Stack stack("plant_sim", kPortPlantSim, false);
  stack.Start();
  ASSERT_TRUE(stack.WaitArmed(10.0)) << "the stack did not arm";
  const StackConfig& c = stack.config();
  const double hb_ms = 1e3 * c.supervisor.heartbeat_timeout_s;
  HeldFaultRounds(
      stack, &rng, "plant_sim", &stack.plant, [&] { return stack.StartPlantSim(); },
      [&](bool kill, const SafeTimes& t) {
        if (kill) {
          // The new plant_sim's first heartbeat: a restart, judged at once.
          EXPECT_LT(*t.hold_ms, hb_ms) << t.hold_reason;
        } else {
          EXPECT_LE(*t.hold_ms, hb_ms + 1e3 / c.lcm.health_rate_hz + 150.0);
          EXPECT_GE(*t.hold_ms, hb_ms - 1e3 / c.lcm.health_rate_hz - 10.0);
        }
      });
}

/// One process stopped and killed whose loss the supervisor holds on: the
/// estimator (no state: no safe command, the actuators' command timeout; a
/// restarted one starts over and is judged a restart, or its first
/// estimates are not usable), the controller (no nominal: the safety
/// process's watchdog; a restarted one is judged a restart), and in
/// hardware mode hw_emulator (the device: hw_bridge's link times out and it
/// reports FAULT) or hw_bridge (no sensor_t at all; its heartbeat stops, or
/// restarts; the device's watchdog cuts the drive). Either way the
/// supervisor holds within the detection time, and after the operator's
/// reset and resume the platform moves on.
void OneProcessStoppedAndKilled(const std::string& name, int port, uint64_t seed_stream) {
  test::LauncherLock lock;
  PrintSeed();
  std::mt19937_64 rng(Seed() * 4 + seed_stream);
  const bool hardware = name == "hw_bridge" || name == "hw_emulator";
  Stack stack(name, port, hardware);
  stack.Start();
  ASSERT_TRUE(stack.WaitArmed(hardware ? 15.0 : 10.0)) << "the stack did not arm";
  const StackConfig& c = stack.config();
  const std::map<std::string, std::unique_ptr<test::ChildProcess>*> targets = {
      {"estimator", &stack.estimator},
      {"controller", &stack.controller},
      {"hw_bridge", &stack.bridge},
      {"hw_emulator", &stack.emulator}};
  // What tells the supervisor (a heartbeat lost, or for the device the
  // bridge's link timeout and its FAULT heartbeat), a heartbeat period, and
  // slack for a loaded host.
  const double detect_s =
      name == "hw_emulator" ? c.hw_bridge.link_timeout_s : c.supervisor.heartbeat_timeout_s;
  const double hold_bound_ms = 1e3 * detect_s + 1e3 / c.lcm.health_rate_hz + 150.0;
  HeldFaultRounds(
      stack, &rng, name, targets.at(name),
      [&]() -> std::unique_ptr<test::ChildProcess> {
        if (name == "estimator") return stack.StartEstimator();
        if (name == "controller") return stack.StartController();
        return name == "hw_bridge" ? stack.StartBridge() : stack.StartEmulator();
      },
      [&](bool, const SafeTimes& t) { EXPECT_LE(*t.hold_ms, hold_bound_ms) << t.hold_reason; });
}

TEST(ProcessFaults, EstimatorStoppedAndKilled) {
  OneProcessStoppedAndKilled("estimator", kPortEstimator, 5);
}

TEST(ProcessFaults, ControllerStoppedAndKilled) {
  OneProcessStoppedAndKilled("controller", kPortController, 6);
}

// The safety process dies or stops: no safe command; the actuators' command
// timeout (plant_sim.command_timeout_s) turns them off. A new safety process
// starts DISARMED with a new session; a stopped one, continued, holds.
TEST(ProcessFaults, SafetyStoppedAndKilled) {
  test::LauncherLock lock;
  PrintSeed();
  std::mt19937_64 rng(Seed() * 4 + 1);
  Stack stack("safety", kPortSafety, false);
  stack.Start();
  ASSERT_TRUE(stack.WaitArmed(10.0)) << "the stack did not arm";
  const StackConfig& c = stack.config();
  const double off_bound_ms = 1e3 * c.plant_sim.command_timeout_s + 2e3 / c.sensors.rate_hz + 150.0;
  const auto started = std::chrono::steady_clock::now();
  int rounds = 0;
  do {
    for (const bool kill : {false, true}) {
      const std::string what = std::string("safety ") + (kill ? "kill" : "stop");
      const FaultRun run = InjectFault(
          stack, &rng, "safety", &stack.safety, kill, StopSeconds(c),
          [&] { return stack.StartSafety(/*auto_arm=*/false); },
          [&](const SafeTimes& t) {
            return t.actuators_off_ms.has_value() && (kill || t.hold_ms.has_value());
          },
          StopSeconds(c) + 2.0);
      ASSERT_TRUE(run.times.actuators_off_ms) << what << ": the actuators stayed on";
      EXPECT_LE(*run.times.actuators_off_ms, off_bound_ms);
      if (!kill) {
        EXPECT_TRUE(run.times.hold_ms) << what << ": the continued safety did not hold";
      }
      ExpectOperatorRecovery(stack, run, kill ? "arm" : "resume", 1.0, what);
      const CounterDelta d = Counters(stack.bus, run.fault_us, WallUs());
      PrintCounters(what, d);
      EXPECT_GT(d.Of("plant_sim", "command_timeouts"), 0) << what;
      ExpectAllRunning(stack, "", "after " + what);
      ASSERT_TRUE(stack.WaitArmed(5.0, WallUs() - 1'000'000)) << what << ": not back to normal";
    }
  } while (SoakGoesOn(started, &rounds));
  std::printf("[process-fault] safety: %d round(s); %s\n", rounds,
              test::Describe(stack.bus.truth).c_str());
  test::ExpectWithinLimits(stack.bus.truth);
  ExpectTheLogHasEverySampleHeard(stack);
}

// The emulated device stops or dies: no sensor frame, so hw_bridge's link
// goes down (hw_bridge.link_timeout_s: a FAULT heartbeat) and the stack has
// no state; the device's own watchdog zeroes the drive. A restarted device
// follows the bridge's link session again (docs/wire-protocol.md).
TEST(ProcessFaults, HwEmulatorStoppedAndKilled) {
  OneProcessStoppedAndKilled("hw_emulator", kPortHwEmulator, 3);
}

// The bridge stopped: it holds a backlog of the device's frames and of safe
// commands when it is continued; killed, a new bridge starts a new link
// session the device follows (docs/wire-protocol.md, "Sessions").
TEST(ProcessFaults, HwBridgeStoppedAndKilled) {
  OneProcessStoppedAndKilled("hw_bridge", kPortHwBridge, 0x5bd1e995);
}

/// stewart_log_export --check on `log`: its output (the check's lines) and
/// the continuity JSON's events.
struct LogCheck {
  int exit_code = -1;
  std::string text;
  std::vector<std::map<std::string, int64_t>>
      gaps;  // utime_us, previous_utime_us, log_utime_us, missing
  long missing = 0, restarts = 0;
};

LogCheck CheckLog(const std::string& log, const std::string& folder) {
  LogCheck check;
  const std::string out = folder + "/check.txt", json = folder + "/continuity.json";
  check.exit_code = test::Shell(test::ShellQuote(LOG_EXPORT_PATH) + " " + test::ShellQuote(log) +
                                " --check --continuity-json " + test::ShellQuote(json) + " >" +
                                test::ShellQuote(out) + " 2>&1");
  check.text = test::ReadFile(out);
  // The JSON's events, read with the little this test needs: one event per
  // line of the array is not guaranteed, so the numbers are taken by key.
  const std::string j = test::ReadFile(json);
  const auto number_after = [&](size_t at, const std::string& key) -> std::optional<int64_t> {
    const size_t k = j.find("\"" + key + "\":", at);
    if (k == std::string::npos) return std::nullopt;
    return std::strtoll(j.c_str() + k + key.size() + 3, nullptr, 10);
  };
  check.missing = number_after(0, "missing").value_or(-1);
  check.restarts = number_after(0, "restarts").value_or(-1);
  const std::string kGapKind = "\"kind\": \"gap\"";
  for (size_t at = j.find("\"kind\""); at != std::string::npos; at = j.find("\"kind\"", at + 1)) {
    if (j.compare(at, kGapKind.size(), kGapKind) != 0) continue;
    std::map<std::string, int64_t> e;
    for (const char* key : {"utime_us", "previous_utime_us", "log_utime_us", "missing"}) {
      e[key] = number_after(at, key).value_or(-1);
    }
    check.gaps.push_back(e);
  }
  return check;
}

// The recorder is no part of the loop: stopped or killed, the stack goes on
// (no HOLD, no fallback, the actuators on); what it missed is named by the
// log's check, and only there.
TEST(ProcessFaults, LoggerStoppedAndKilled) {
  test::LauncherLock lock;
  PrintSeed();
  std::mt19937_64 rng(Seed() * 4 + 2);
  Stack stack("logger", kPortLogger, false);
  stack.Start();
  ASSERT_TRUE(stack.WaitArmed(10.0)) << "the stack did not arm";
  const StackConfig& c = stack.config();
  constexpr double kLoggerStopS = 0.5;
  struct Window {
    int64_t from_us, to_us;
  };
  std::vector<Window> windows;
  const auto started = std::chrono::steady_clock::now();
  int rounds = 0;
  do {
    for (const bool kill : {false, true}) {
      const std::string what = std::string("stewart_logger ") + (kill ? "kill" : "stop");
      const FaultRun run = InjectFault(
          stack, &rng, "stewart_logger", &stack.logger, kill, kLoggerStopS,
          [&] { return stack.StartLogger(/*append=*/true); },
          [](const SafeTimes&) { return false; }, 1.0);
      windows.push_back({run.fault_us, run.resumed_us});
      EXPECT_FALSE(run.times.hold_ms) << what << ": " << run.times.hold_reason;
      EXPECT_FALSE(run.times.fallback_ms) << what;
      EXPECT_FALSE(run.times.actuators_off_ms) << what;
      for (const auto& s : stack.bus.supervisor) {
        if (s.recv_us >= run.fault_us) {
          EXPECT_EQ(int{s.msg.state}, int{supervisor_state_t::STATE_ARMED})
              << what << ": " << s.msg.reason;
        }
      }
      const CounterDelta d = Counters(stack.bus, run.fault_us, WallUs());
      PrintCounters(what, d);
      ExpectAllRunning(stack, "", "after " + what);
    }
  } while (SoakGoesOn(started, &rounds));
  (void)c;
  ASSERT_EQ(stack.logger->Stop(SIGTERM), 0);
  const LogCheck check = CheckLog(stack.log_path(), stack.folder());
  std::printf("[process-fault] stewart_logger: the log's check says:\n%s", check.text.c_str());
  EXPECT_EQ(check.exit_code, 0) << check.text;
  // Named: a warning, the messages missing, per stream.
  EXPECT_NE(check.text.find("WARNING"), std::string::npos) << check.text;
  ASSERT_GT(check.missing, 0) << "a killed logger lost nothing?";
  ASSERT_FALSE(check.gaps.empty());
  // Every gap is one of the faults': it closes (the first message after it
  // recorded) after a fault and within 1 s of the logger's return.
  std::vector<long> lost(windows.size(), 0);
  for (const auto& g : check.gaps) {
    // The latest fault before the gap closed.
    const int64_t closed_us = g.at("log_utime_us");
    size_t w = windows.size();
    while (w > 0 && windows[w - 1].from_us > closed_us) --w;
    const bool in_window = w > 0 && closed_us <= windows[w - 1].to_us + 1'000'000;
    if (in_window) lost[w - 1] += g.at("missing");
    EXPECT_TRUE(in_window) << "a gap outside the faults, closing at " << closed_us << " us ("
                           << g.at("missing") << " missing)";
  }
  for (size_t w = 0; w < windows.size(); ++w) {
    std::printf("[process-fault]   stewart_logger %s %.1f ms: %ld messages missing from the log\n",
                w % 2 == 0 ? "stop" : "kill", 1e-3 * double(windows[w].to_us - windows[w].from_us),
                lost[w]);
  }
  // The killed logger's gap at least: messages published while none ran.
  EXPECT_GT(lost[1], 0);
  test::ExpectWithinLimits(stack.bus.truth);
}

}  // namespace
}  // namespace stewart
