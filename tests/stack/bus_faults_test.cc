// Hostile traffic on the bus of a running stack: the real processes in real
// time (plant_sim at 1 kHz, with the run's message key, armed by the
// supervisor, its physics not the model's), and stewart_inject putting on
// every channel, one after the other for a second each: a flood of first
// fragments each declaring 16 MiB (1000 per second), random datagrams (1000
// per second), and the stack's own messages sent again cut short, with the
// wrong fingerprint, duplicated, 10 s stale and 10 s in the future, each
// whole and then cut into fragments of 64 bytes (LCM sends these small
// messages whole); then the loop's messages resent with NaN and with Inf
// values (a plausible time, values to refuse), whole and fragmented, and the
// sensor clock jumping 0.5 s back and 0.5 s
// forward for a second each (a second time base within lcm.time_window_s).
//
// For the whole run: no process dies, no loop stalls (the sensor stream and
// every heartbeat keep coming), every limit holds on the recorded ground
// truth, and each kind of fault is counted where it lands; the recorder
// loses no sensor sample up to the resent copies (see below). docs/operations.md, "Faults on the
// bus".
//
// LCM port 8010 (this file owns 8010-8019). It holds the launcher lock of
// the build folder, as the launched-stack tests do.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <lcm/lcm-cpp.hpp>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "stewart/config/config_loader.h"
#include "stewart/force_command_t.hpp"
#include "stewart/health_t.hpp"
#include "stewart/node/lcm_handle.h"
#include "stewart/node/lcm_receiver.h"
#include "stewart/safety_diagnostics_t.hpp"
#include "stewart/sensor_t.hpp"
#include "stewart/setpoint_t.hpp"
#include "stewart/state_t.hpp"
#include "stewart/supervisor_state_t.hpp"
#include "stewart/test_support/child_process.h"
#include "stewart/test_support/health_counter.h"
#include "stewart/test_support/recorded_run.h"
#include "stewart/test_support/stack_launch.h"

namespace stewart {
namespace {

constexpr int kPort = 8010;

template <typename T, size_t N>
bool Finite(const T (&values)[N]) {
  return std::all_of(std::begin(values), std::end(values), [](T v) { return std::isfinite(v); });
}
bool Finite(const std::vector<double>& values) {
  return std::all_of(values.begin(), values.end(), [](double v) { return std::isfinite(v); });
}
bool Finite(const sensor_t& m) {
  return Finite(m.leg_length_m) && Finite(m.gyro_radps) && Finite(m.accel_mps2) &&
         Finite(m.orientation_rpy_rad);
}
bool Finite(const state_t& m) {
  return Finite(m.q) && Finite(m.qd) && Finite(m.q_std) && Finite(m.qd_std) &&
         Finite(m.disturbance) && Finite(m.disturbance_std);
}
bool Finite(const force_command_t& m) { return Finite(m.force_n); }
bool Finite(const setpoint_t& m) {
  return Finite(m.q_des) && Finite(m.qd_des) && Finite(m.qdd_des);
}
bool Finite(const safety_diagnostics_t& m) {
  const double scalars[] = {m.h_pos, m.h_vel, m.psi_p,           m.psi_v,
                            m.mu_p,  m.mu_v,  m.correction_norm, m.nominal_scale};
  return Finite(scalars) && Finite(m.h_position) && Finite(m.alpha_h_position) &&
         Finite(m.w_position) && Finite(m.mu_position) && Finite(m.h_velocity) &&
         Finite(m.alpha_h_velocity) && Finite(m.w_velocity) && Finite(m.mu_velocity) &&
         Finite(m.g_p) && Finite(m.g_v) && Finite(m.mu_force) && Finite(m.f_des) &&
         Finite(m.f_nominal) && Finite(m.f_safe);
}

/// Non-finite messages on one channel, told apart by their origin: a copy
/// stewart_inject poisoned carries the utime of a finite message of the
/// channel and that message's seq + 1 (no publisher of the stack sends two
/// messages with one utime and consecutive seqs). The test's own socket may
/// miss the original in a flood; the stack's own message with that seq, at
/// a later utime, then tells the copy too. Any other non-finite message came
/// from the stack.
struct NonFiniteWatch {
  template <typename Msg>
  void Observe(const Msg& m) {
    if (Finite(m)) {
      finite.emplace(m.utime, m.seq);
      finite_by_seq.emplace(m.seq, m.utime);
    } else {
      non_finite.emplace_back(m.utime, m.seq);
    }
  }
  bool IsCopy(int64_t utime, int64_t seq) const {
    if (finite.count({utime, seq - 1})) return true;
    const auto later = finite_by_seq.lower_bound({seq, utime + 1});
    return later != finite_by_seq.end() && later->first == seq;
  }
  /// Poisoned copies (`injected`) and the rest, the stack's own.
  long FromStack(long* injected) const {
    long own = 0;
    *injected = 0;
    for (const auto& [utime, seq] : non_finite) {
      (IsCopy(utime, seq) ? *injected : own) += 1;
    }
    return own;
  }
  std::set<std::pair<int64_t, int64_t>> finite;
  std::set<std::pair<int64_t, int64_t>> finite_by_seq;  ///< (seq, utime)
  std::vector<std::pair<int64_t, int64_t>> non_finite;
};

struct Bus {
  template <typename Msg>
  void Watch(const lcm::ReceiveBuffer*, const std::string& channel, const Msg* m) {
    watch[channel].Observe(*m);
  }
  void OnEstimate(const lcm::ReceiveBuffer* b, const std::string& channel, const state_t* m) {
    Watch(b, channel, m);
    last_estimate_utime = std::max(last_estimate_utime, m->utime);
    if (Finite(*m)) last_finite_estimate_utime = m->utime;
  }
  void OnSensor(const lcm::ReceiveBuffer* b, const std::string& channel, const sensor_t* m) {
    watch[channel].Observe(*m);
    // The plant's samples only: resent, poisoned or jumped copies repeat
    // or trail its seq.
    if (m->seq <= last_sensor_seq || !Finite(*m)) return;
    last_sensor_utime = m->utime;
    last_sensor_seq = m->seq;
    if (last_sensor_us > 0)
      longest_sensor_gap_us = std::max(longest_sensor_gap_us, b->recv_utime - last_sensor_us);
    last_sensor_us = b->recv_utime;
    ++sensors;
  }
  void OnHealth(const lcm::ReceiveBuffer* b, const std::string&, const health_t* m) {
    auto [it, fresh] = last_health_us.try_emplace(m->name, b->recv_utime);
    if (!fresh) {
      int64_t& gap = longest_health_gap_us[m->name];
      gap = std::max(gap, b->recv_utime - it->second);
      it->second = b->recv_utime;
    }
    health[m->name] = *m;
  }
  void OnSupervisor(const lcm::ReceiveBuffer*, const std::string&, const supervisor_state_t* m) {
    if (supervisor.empty() || supervisor.back().state != m->state) {
      supervisor.push_back(*m);
      supervisor_heard_at.push_back(std::chrono::steady_clock::now());
    }
  }
  int64_t sensors = 0;
  int64_t last_sensor_seq = -1;
  int64_t last_sensor_utime = 0;
  int64_t last_estimate_utime = 0;
  int64_t last_finite_estimate_utime = 0;
  std::map<std::string, NonFiniteWatch> watch;
  int64_t last_sensor_us = 0;
  int64_t longest_sensor_gap_us = 0;
  std::map<std::string, int64_t> last_health_us, longest_health_gap_us;
  std::map<std::string, health_t> health;
  std::vector<supervisor_state_t> supervisor;
  std::vector<std::chrono::steady_clock::time_point> supervisor_heard_at;
};

/// Sensor samples the recorder missed: gaps in sensor_t.seq in the log.
/// Sensor samples the recorder missed among those before `before_seq`
/// (all of them in `*missing_later`).
int64_t SensorSamplesMissingFromLog(const std::string& log_path, const std::string& channel,
                                    int64_t before_seq, int64_t* recorded, int64_t* missing_later) {
  lcm::LogFile log(log_path, "r");
  int64_t missing = 0, last_seq = -1;
  *recorded = 0;
  *missing_later = 0;
  if (!log.good()) return -1;
  while (const lcm::LogEvent* event = log.readNextEvent()) {
    if (event->channel != channel) continue;
    sensor_t s;
    if (s.decode(event->data, 0, event->datalen) < 0) continue;
    // The plant's samples only: resent, poisoned or jumped copies repeat or
    // trail its seq.
    if (s.seq <= last_seq || !Finite(s)) continue;
    ++*recorded;
    if (last_seq >= 0 && s.seq > last_seq + 1) {
      (s.seq <= before_seq ? missing : *missing_later) += s.seq - last_seq - 1;
      std::printf("[bus faults] recorder missed sensor samples %lld-%lld (before %.3f s)\n",
                  static_cast<long long>(last_seq + 1), static_cast<long long>(s.seq - 1),
                  1e-6 * static_cast<double>(s.utime));
    }
    last_seq = s.seq;
  }
  return missing;
}

TEST(BusFaults, HostileTrafficOnEveryChannelIsCountedAndChangesNothingUnsafe) {
  test::LauncherLock lock;
  std::string folder = "/tmp/stewart_bus_faults_XXXXXX";
  ASSERT_NE(mkdtemp(folder.data()), nullptr);
  const std::string log_path = folder + "/log.lcm";
  const std::string key = folder + "/run.key";
  std::ofstream(key) << "5eed5eed0badc0ffee0123456789abcdef0123456789abcdef0123456789abcd\n";
  ::chmod(key.c_str(), 0600);
  const std::string overlay =
      test::WriteAutoArmOverlay(folder, "lcm:\n  auth_key_file: \"" + key + "\"\n");
  const StackConfig config = LoadStackConfig(DefaultConfigPath(), {overlay});
  const auto& ch = config.lcm.channels;
  const std::string url = PrivateLcmUrl(kPort);
  const auto with = [&](std::vector<std::string> argv) {
    return test::WithStackFlags(std::move(argv), url, overlay);
  };

  LcmReceiver receiver(url);
  Bus bus;
  receiver.Subscribe(ch.sensors, &Bus::OnSensor, &bus);
  receiver.Subscribe(ch.state_estimate, &Bus::OnEstimate, &bus);
  receiver.Subscribe(ch.command_nominal, &Bus::Watch<force_command_t>, &bus);
  receiver.Subscribe(ch.command_safe, &Bus::Watch<force_command_t>, &bus);
  receiver.Subscribe(ch.setpoint, &Bus::Watch<setpoint_t>, &bus);
  receiver.Subscribe(ch.safety_diagnostics, &Bus::Watch<safety_diagnostics_t>, &bus);
  receiver.Subscribe(ch.health, &Bus::OnHealth, &bus);
  receiver.Subscribe(ch.supervisor, &Bus::OnSupervisor, &bus);
  const auto pump_until = [&](auto done, double timeout_s) {
    return test::PumpUntil(&receiver, done, timeout_s);
  };

  test::StackWithoutPlant stack({LOGGER_PATH, SAFETY_PATH, CONTROLLER_PATH, ESTIMATOR_PATH}, url,
                                log_path, with);
  ASSERT_TRUE(stack.started());
  ASSERT_TRUE(pump_until(
      [&] {
        return bus.health.count("safety") && bus.health.count("controller") &&
               bus.health.count("estimator");
      },
      15.0))
      << "the stack did not come up";
  constexpr double kDurationS = 36.0;
  // The plant is not the model (heavier, a payload, joint errors, friction,
  // gains, a push: test::WriteMismatchedTruth).
  test::ChildProcess plant(
      with({PLANT_SIM_PATH, "--mode", "realtime", "--duration", std::to_string(kDurationS),
            "--truth", test::WriteMismatchedTruth(folder)}));
  ASSERT_TRUE(plant.started());
  ASSERT_TRUE(pump_until(
      [&] {
        return !bus.supervisor.empty() &&
               bus.supervisor.back().state == supervisor_state_t::STATE_ARMED && bus.sensors > 1000;
      },
      10.0))
      << "the supervisor did not arm: " << bus.sensors << " sensor samples, "
      << bus.supervisor.size() << " supervisor states, last "
      << (bus.supervisor.empty()
              ? std::string("none")
              : std::to_string(bus.supervisor.back().state) + " " + bus.supervisor.back().reason);

  // Each fault for a second, then half a second of quiet; the counters of
  // the process that receives it, before and after. A name ending in
  // "-fragmented": the same traffic, each message in fragments of 64 bytes.
  struct Fault {
    std::string mode;
    std::vector<std::string> extra;
  };
  const std::vector<std::string> nan_channels = {
      "--channel", ch.sensors,  "--channel",        ch.state_estimate, "--channel",
      ch.setpoint, "--channel", ch.command_nominal, "--channel",       ch.command_safe};
  const auto with_channels = [&](std::vector<std::string> extra) {
    extra.insert(extra.end(), nan_channels.begin(), nan_channels.end());
    return extra;
  };
  const std::vector<Fault> faults = {
      {"fragment-flood", {"--rate-hz", "1000"}},
      {"garbage", {"--rate-hz", "1000"}},
      {"truncate", {"--rate-hz", "500"}},
      {"wrong-fingerprint", {"--rate-hz", "500"}},
      {"duplicate", {"--rate-hz", "500"}},
      {"stale", {"--rate-hz", "500", "--shift-s", "10"}},
      {"future", {"--rate-hz", "500", "--shift-s", "10"}},
      {"garbage-fragmented", {"--rate-hz", "1000"}},
      {"truncate-fragmented", {"--rate-hz", "500"}},
      {"wrong-fingerprint-fragmented", {"--rate-hz", "500"}},
      {"duplicate-fragmented", {"--rate-hz", "500"}},
      {"stale-fragmented", {"--rate-hz", "500", "--shift-s", "10"}},
      {"future-fragmented", {"--rate-hz", "500", "--shift-s", "10"}},
      // The loop's messages with a plausible time and NaN / Inf values; not
      // the ground truth, which no process of this stack reads and which is
      // this test's reference.
      {"nan", with_channels({"--rate-hz", "500"})},
      {"inf", with_channels({"--rate-hz", "500"})},
      {"nan-fragmented", with_channels({"--rate-hz", "500"})},
      {"inf-fragmented", with_channels({"--rate-hz", "500"})},
      // A second sensor clock, within lcm.time_window_s of the plant's: back,
      // then forward (last: see docs/operations.md, "Time plausibility").
      {"clock-jump-back", {"--rate-hz", "5000", "--shift-s", "-0.5"}},
      {"clock-jump-forward", {"--rate-hz", "5000", "--shift-s", "0.5"}},
  };
  const std::vector<std::string> watched = {ch.sensors,         ch.state_estimate,
                                            ch.command_nominal, ch.command_safe,
                                            ch.setpoint,        ch.safety_diagnostics};
  const auto injected_now = [&] {
    std::map<std::string, long> n;
    for (const std::string& c : watched) bus.watch[c].FromStack(&n[c]);
    return n;
  };
  std::map<std::string, health_t> before, after;
  std::map<std::string, std::map<std::string, health_t>> before_all, after_all;
  std::map<std::string, std::map<std::string, long>> injected_before, injected_after;
  std::map<std::string, int64_t> first_sample;
  std::chrono::steady_clock::time_point jump_forward_start{};
  double jump_recovery_s = -1.0;
  int8_t supervisor_before_jump = -1;
  for (const Fault& fault : faults) {
    before[fault.mode] = bus.health["safety"];
    before_all[fault.mode] = bus.health;
    if (fault.mode == "clock-jump-forward" && !bus.supervisor.empty()) {
      supervisor_before_jump = bus.supervisor.back().state;
    }
    injected_before[fault.mode] = injected_now();
    first_sample[fault.mode] = bus.last_sensor_seq;
    std::printf("[bus faults] %s from sensor sample %lld\n", fault.mode.c_str(),
                static_cast<long long>(bus.last_sensor_seq));
    const std::string kFragmented = "-fragmented";
    const bool fragmented = fault.mode.size() > kFragmented.size() &&
                            fault.mode.compare(fault.mode.size() - kFragmented.size(),
                                               kFragmented.size(), kFragmented) == 0;
    const std::string mode =
        fault.mode.rfind("clock-jump", 0) == 0
            ? "clock-jump"
            : fault.mode.substr(0, fault.mode.size() - (fragmented ? kFragmented.size() : 0));
    std::vector<std::string> argv = {INJECT_PATH, "--mode", mode, "--duration-s", "1.0"};
    argv.insert(argv.end(), fault.extra.begin(), fault.extra.end());
    if (fragmented) argv.insert(argv.end(), {"--fragment-bytes", "64"});
    if (fault.mode == "clock-jump-forward") jump_forward_start = std::chrono::steady_clock::now();
    test::ChildProcess inject(with(argv));
    ASSERT_TRUE(inject.started());
    ASSERT_TRUE(pump_until([&] { return !inject.running(); }, 10.0)) << fault.mode;
    EXPECT_EQ(inject.exit_code(), 0) << fault.mode;
    if (fault.mode == "clock-jump-forward") {
      // Back on the plant's clock: the estimates follow the plant's samples
      // again (a jump of 0.5 s: the old clock's samples are out of order
      // until it has passed the newest jumped one).
      const auto end = std::chrono::steady_clock::now();
      if (pump_until(
              [&] {
                return bus.last_finite_estimate_utime <= bus.last_sensor_utime &&
                       bus.last_sensor_utime - bus.last_finite_estimate_utime < 20'000;
              },
              3.0)) {
        jump_recovery_s =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - end).count();
      }
    }
    // A heartbeat after the fault ended (2 Hz).
    pump_until([] { return false; }, 0.6);
    after[fault.mode] = bus.health["safety"];
    after_all[fault.mode] = bus.health;
    injected_after[fault.mode] = injected_now();
  }
  ASSERT_TRUE(pump_until([&] { return !plant.running(); }, kDurationS + 20.0))
      << "plant_sim did not finish";
  EXPECT_EQ(plant.exit_code(), 0);
  pump_until([] { return false; }, 0.6);
  for (test::ChildProcess* p :
       {&stack.safety, &stack.controller, &stack.estimator, &stack.logger}) {
    EXPECT_TRUE(p->running()) << "a stack process died";
  }

  std::printf("[bus faults] longest gap: sensor stream %.1f ms", 1e-3 * bus.longest_sensor_gap_us);
  for (const auto& [name, gap] : bus.longest_health_gap_us) {
    std::printf(", %s heartbeat %.0f ms", name.c_str(), 1e-3 * gap);
  }
  std::printf("\n");
  for (const auto& [mode, h] : after) {
    const health_t& b = before[mode];
    std::printf(
        "[bus faults] %-17s safety: rx_bad +%lld, rx_decode_fail +%lld, rx_incomplete +%lld, "
        "rejected +%lld\n",
        mode.c_str(),
        static_cast<long long>(test::HealthCounter(h, "rx_bad") - test::HealthCounter(b, "rx_bad")),
        static_cast<long long>(test::HealthCounter(h, "rx_decode_fail") -
                               test::HealthCounter(b, "rx_decode_fail")),
        static_cast<long long>(test::HealthCounter(h, "rx_incomplete") -
                               test::HealthCounter(b, "rx_incomplete")),
        static_cast<long long>(h.rejected_inputs - b.rejected_inputs));
  }
  for (const supervisor_state_t& s : bus.supervisor) {
    std::printf("[bus faults] supervisor state %d (%s)\n", s.state, s.reason.c_str());
  }
  std::fflush(stdout);

  // No loop stalled: the plant's samples kept coming (1 kHz; a starved
  // scheduler on this 2-core machine is allowed tens of ms), and every
  // process kept beating (rates.health_hz 2: 0.5 s apart).
  EXPECT_LT(bus.longest_sensor_gap_us, 100'000);
  for (const char* name : {"plant_sim", "safety", "controller", "estimator"}) {
    ASSERT_TRUE(bus.longest_health_gap_us.count(name)) << name;
    EXPECT_LT(bus.longest_health_gap_us[name], 1'000'000) << name;
  }
  // Each fault counted where it landed: the safety process subscribes to
  // STATE_EST, CMD_NOMINAL, SETPOINT, HEALTH and OPERATOR.
  const auto delta = [&](const std::string& mode, const std::string& counter) {
    return test::HealthCounter(after[mode], counter) - test::HealthCounter(before[mode], counter);
  };
  const auto rejected = [&](const std::string& mode) {
    return after[mode].rejected_inputs - before[mode].rejected_inputs;
  };
  EXPECT_GT(delta("fragment-flood", "rx_incomplete"), 0);
  for (const std::string form : {"", "-fragmented"}) {
    EXPECT_GT(delta("garbage" + form, "rx_decode_fail"), 0) << form;
    EXPECT_GT(delta("truncate" + form, "rx_decode_fail"), 0) << form;
    EXPECT_GT(delta("wrong-fingerprint" + form, "rx_decode_fail"), 0) << form;
    EXPECT_GT(rejected("duplicate" + form), 0) << form;
    EXPECT_GT(rejected("stale" + form), 0) << form;
    EXPECT_GT(rejected("future" + form), 0) << form;
  }
  // Cut into fragments, a message is reassembled and then judged as the
  // whole one is: the counts above, and the poisoned copies below refused
  // one for one. (A fragment the kernel dropped under the 1000/s garbage,
  // up to 8 fragments each, leaves its message incomplete: counted,
  // rx_incomplete, printed above.)

  // No process published a non-finite value, whatever it was sent.
  for (const std::string& c : watched) {
    long injected = 0;
    EXPECT_EQ(bus.watch[c].FromStack(&injected), 0) << "non-finite values published on " << c;
    std::printf("[bus faults] %s: %zu finite, %ld poisoned copies heard\n", c.c_str(),
                bus.watch[c].finite.size(), injected);
  }
  // Each poisoned copy refused by the process that received it, counted
  // under its name: the copies the test heard against the counter's growth
  // (a process or the test may miss a datagram of a flood; printed).
  const auto grew = [&](const std::string& mode, const std::string& process,
                        const std::string& counter) {
    return test::HealthCounter(after_all[mode][process], counter) -
           test::HealthCounter(before_all[mode][process], counter);
  };
  const auto heard = [&](const std::string& mode, const std::string& channel) {
    return injected_after[mode][channel] - injected_before[mode][channel];
  };
  for (const std::string mode : {"nan", "inf", "nan-fragmented", "inf-fragmented"}) {
    const long states = heard(mode, ch.state_estimate), nominals = heard(mode, ch.command_nominal);
    const long samples = heard(mode, ch.sensors), safe = heard(mode, ch.command_safe);
    std::printf(
        "[bus faults] %s copies heard: %ld states, %ld nominal, %ld samples, %ld safe commands; "
        "controller state_non_finite +%lld, safety nonfinite_state +%lld, nominal_non_finite "
        "+%lld, estimator non_increasing_time +%lld, command_non_finite +%lld, plant_sim "
        "command_unauthentic +%lld\n",
        mode.c_str(), states, nominals, samples, safe,
        static_cast<long long>(grew(mode, "controller", "rejected_state_non_finite")),
        static_cast<long long>(grew(mode, "safety", "rejected_nonfinite_state")),
        static_cast<long long>(grew(mode, "safety", "rejected_nominal_non_finite")),
        static_cast<long long>(grew(mode, "estimator", "rejected_non_increasing_time")),
        static_cast<long long>(grew(mode, "estimator", "rejected_command_non_finite")),
        static_cast<long long>(grew(mode, "plant_sim", "rejected_command_unauthentic")));
    EXPECT_GT(states, 0) << mode;
    EXPECT_GT(nominals, 0) << mode;
    EXPECT_GT(samples, 0) << mode;
    EXPECT_GT(safe, 0) << mode;
    // State estimates: the controller and the safety process each refuse
    // every copy for its values.
    EXPECT_GE(grew(mode, "controller", "rejected_state_non_finite"), states * 95 / 100) << mode;
    EXPECT_GE(grew(mode, "safety", "rejected_nonfinite_state"), states * 95 / 100) << mode;
    // Nominal commands: refused before they can wait for their state.
    EXPECT_GE(grew(mode, "safety", "rejected_nominal_non_finite"), nominals * 95 / 100) << mode;
    // Sensor samples: a copy carries its original's utime, which the
    // estimator has answered: refused as out of order before its values.
    EXPECT_GE(grew(mode, "estimator", "rejected_non_increasing_time"), samples * 95 / 100) << mode;
    // Safe commands: the estimator refuses them for their values; the
    // actuator, with a key, for the MAC the values no longer match.
    EXPECT_GE(grew(mode, "estimator", "rejected_command_non_finite"), safe * 95 / 100) << mode;
    EXPECT_GE(grew(mode, "plant_sim", "rejected_command_unauthentic"), safe * 95 / 100) << mode;
  }
  // The clock jumps: the other clock's samples are refused and counted by
  // the estimator (back: out of order; forward: the plant's own samples are
  // out of order while the jumped clock leads, then the loop returns to the
  // plant's clock), and no command of the jumped clock moves the platform.
  std::printf("[bus faults] clock-jump-back: estimator rejected +%lld\n",
              static_cast<long long>(after_all["clock-jump-back"]["estimator"].rejected_inputs -
                                     before_all["clock-jump-back"]["estimator"].rejected_inputs));
  EXPECT_GT(grew("clock-jump-back", "estimator", "rejected_non_increasing_time"), 500);
  std::printf(
      "[bus faults] clock-jump-forward: back on the plant's clock %.2f s after the jump ended; "
      "estimator non_increasing_time +%lld, reinit_time_gap +%lld; plant_sim "
      "command_future_sample +%lld, command_timeouts +%lld; estimator fault %s\n",
      jump_recovery_s,
      static_cast<long long>(
          grew("clock-jump-forward", "estimator", "rejected_non_increasing_time")),
      static_cast<long long>(grew("clock-jump-forward", "estimator", "reinit_time_gap")),
      static_cast<long long>(
          grew("clock-jump-forward", "plant_sim", "rejected_command_future_sample")),
      static_cast<long long>(grew("clock-jump-forward", "plant_sim", "command_timeouts")),
      after_all["clock-jump-forward"]["estimator"].latched_error.c_str());
  EXPECT_GE(jump_recovery_s, 0.0) << "the loop did not return to the plant's clock";
  // Back: refused and counted, the estimator never starved. Forward: a
  // fault, not a silent stall: the estimator starved while the plant's
  // samples were behind the jumped clock (FAULT, latched) and the supervisor
  // holds the platform (its estimates restart from the legs, not usable).
  EXPECT_FALSE(after_all["clock-jump-back"]["estimator"].fault_latched);
  EXPECT_TRUE(after_all["clock-jump-forward"]["estimator"].fault_latched);
  EXPECT_GT(grew("clock-jump-forward", "plant_sim", "rejected_command_future_sample"), 0);
  // Every fault before it left the platform armed.
  EXPECT_EQ(supervisor_before_jump, int{supervisor_state_t::STATE_ARMED});
  ASSERT_FALSE(bus.supervisor.empty());
  EXPECT_EQ(bus.supervisor.back().state, int{supervisor_state_t::STATE_HOLD});
  // From the forward jump to HOLD (wall time, as the test heard it): the
  // estimator starves, and the supervisor holds on its fault.
  double jump_to_hold_ms = -1.0;
  for (size_t i = 0; i < bus.supervisor.size(); ++i) {
    if (bus.supervisor[i].state == supervisor_state_t::STATE_HOLD &&
        bus.supervisor_heard_at[i] >= jump_forward_start) {
      jump_to_hold_ms =
          std::chrono::duration<double, std::milli>(bus.supervisor_heard_at[i] - jump_forward_start)
              .count();
      break;
    }
  }
  std::printf("[bus faults] clock-jump-forward: HOLD %.0f ms after the jump began (%s)\n",
              jump_to_hold_ms, bus.supervisor.back().reason.c_str());
  EXPECT_GE(jump_to_hold_ms, 0.0) << "no HOLD after the forward jump";

  stack.logger.Stop(SIGTERM);
  // The recorder must lose nothing while the bus carries floods, garbage,
  // cut and mistyped messages, nor while copies of the stack's own messages
  // are resent (duplicate, stale, future, NaN, Inf, a jumped clock).
  int64_t recorded = 0, missing_later = 0;
  const int64_t missing = SensorSamplesMissingFromLog(
      log_path, ch.sensors, first_sample["duplicate"], &recorded, &missing_later);
  const test::RecordedRun run = test::ReadRecordedRun(log_path, config);
  ASSERT_NE(run.Worst(), nullptr);
  std::printf(
      "[bus faults] recorder: %lld sensor samples, %lld missing before the resent copies, %lld "
      "while they were sent; %s\n",
      static_cast<long long>(recorded), static_cast<long long>(missing),
      static_cast<long long>(missing_later), test::Describe(run).c_str());
  EXPECT_EQ(missing, 0) << "the recorder lost sensor samples";
  EXPECT_EQ(missing_later, 0) << "the recorder lost sensor samples while copies were resent";
  EXPECT_GE(recorded, static_cast<int64_t>(0.9 * kDurationS * config.sensors.rate_hz));
  test::ExpectWithinLimits(run);
  EXPECT_GT(run.max_x, 0.05) << "the platform did not move";
  if (!::testing::Test::HasFailure()) {
    std::error_code ignored;
    std::filesystem::remove_all(folder, ignored);
  } else {
    std::printf("run folder kept: %s\n", folder.c_str());
  }
}

}  // namespace
}  // namespace stewart
