// Hostile traffic on the bus of a running stack: the real processes in real
// time (plant_sim at 1 kHz, with the run's message key, armed by the
// supervisor), and stewart_inject putting on
// every channel, one after the other for a second each: a flood of first
// fragments each declaring 16 MiB (1000 per second), random datagrams (1000
// per second), and the stack's own messages sent again cut short, with the
// wrong fingerprint, duplicated, 10 s stale and 10 s in the future.
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
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <lcm/lcm-cpp.hpp>
#include <map>
#include <string>
#include <vector>

#include "stewart/config/config_loader.h"
#include "stewart/health_t.hpp"
#include "stewart/node/lcm_handle.h"
#include "stewart/node/lcm_receiver.h"
#include "stewart/sensor_t.hpp"
#include "stewart/supervisor_state_t.hpp"
#include "stewart/test_support/child_process.h"
#include "stewart/test_support/recorded_run.h"
#include "stewart/test_support/stack_launch.h"

namespace stewart {
namespace {

constexpr int kPort = 8010;

int64_t Counter(const health_t& h, const std::string& name) {
  for (int i = 0; i < h.num_counters; ++i) {
    if (h.counter_names[static_cast<size_t>(i)] == name) {
      return h.counter_values[static_cast<size_t>(i)];
    }
  }
  return 0;
}

struct Bus {
  void OnSensor(const lcm::ReceiveBuffer* b, const std::string&, const sensor_t* m) {
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
    if (supervisor.empty() || supervisor.back().state != m->state) supervisor.push_back(*m);
  }
  int64_t sensors = 0;
  int64_t last_sensor_seq = -1;
  int64_t last_sensor_us = 0;
  int64_t longest_sensor_gap_us = 0;
  std::map<std::string, int64_t> last_health_us, longest_health_gap_us;
  std::map<std::string, health_t> health;
  std::vector<supervisor_state_t> supervisor;
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
  constexpr double kDurationS = 14.0;
  test::ChildProcess plant(
      with({PLANT_SIM_PATH, "--mode", "realtime", "--duration", std::to_string(kDurationS)}));
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
  // the process that receives it, before and after.
  struct Fault {
    std::string mode;
    std::vector<std::string> extra;
  };
  const std::vector<Fault> faults = {
      {"fragment-flood", {"--rate-hz", "1000"}},
      {"garbage", {"--rate-hz", "1000"}},
      {"truncate", {"--rate-hz", "500"}},
      {"wrong-fingerprint", {"--rate-hz", "500"}},
      {"duplicate", {"--rate-hz", "500"}},
      {"stale", {"--rate-hz", "500", "--shift-s", "10"}},
      {"future", {"--rate-hz", "500", "--shift-s", "10"}},
  };
  std::map<std::string, health_t> before, after;
  std::map<std::string, int64_t> first_sample;
  for (const Fault& fault : faults) {
    before[fault.mode] = bus.health["safety"];
    first_sample[fault.mode] = bus.last_sensor_seq;
    std::printf("[bus faults] %s from sensor sample %lld\n", fault.mode.c_str(),
                static_cast<long long>(bus.last_sensor_seq));
    std::vector<std::string> argv = {INJECT_PATH, "--mode", fault.mode, "--duration-s", "1.0"};
    argv.insert(argv.end(), fault.extra.begin(), fault.extra.end());
    test::ChildProcess inject(with(argv));
    ASSERT_TRUE(inject.started());
    ASSERT_TRUE(pump_until([&] { return !inject.running(); }, 10.0)) << fault.mode;
    EXPECT_EQ(inject.exit_code(), 0) << fault.mode;
    // A heartbeat after the fault ended (2 Hz).
    pump_until([] { return false; }, 0.6);
    after[fault.mode] = bus.health["safety"];
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
        mode.c_str(), static_cast<long long>(Counter(h, "rx_bad") - Counter(b, "rx_bad")),
        static_cast<long long>(Counter(h, "rx_decode_fail") - Counter(b, "rx_decode_fail")),
        static_cast<long long>(Counter(h, "rx_incomplete") - Counter(b, "rx_incomplete")),
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
    return Counter(after[mode], counter) - Counter(before[mode], counter);
  };
  const auto rejected = [&](const std::string& mode) {
    return after[mode].rejected_inputs - before[mode].rejected_inputs;
  };
  EXPECT_GT(delta("fragment-flood", "rx_incomplete"), 0);
  EXPECT_GT(delta("garbage", "rx_decode_fail"), 0);
  EXPECT_GT(delta("truncate", "rx_decode_fail"), 0);
  EXPECT_GT(delta("wrong-fingerprint", "rx_decode_fail"), 0);
  EXPECT_GT(rejected("duplicate"), 0);
  EXPECT_GT(rejected("stale"), 0);
  EXPECT_GT(rejected("future"), 0);

  stack.logger.Stop(SIGTERM);
  // The recorder must lose nothing while the bus carries floods, garbage,
  // cut and mistyped messages. While copies of the stack's own messages are
  // resent (duplicate, stale, future), stewart_logger was measured to miss 1-3
  // samples at a time (18 and 34 of about 4,800 in two runs on a quiet
  // machine): printed, not yet
  // asserted (docs/operations.md, "Faults on the bus").
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
