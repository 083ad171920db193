// The attacks found on the running stack, on a lockstep run of the real
// processes (plant_sim --mode lockstep, estimator, controller --scenario
// paper, safety, stewart_logger) on a private URL. Mid-run the test
// publishes, with valid fingerprints:
//   - a STATE_EST at utime 8e18 us (it made the safety and controller
//     processes reject every real state, and safety answered it with a
//     command the estimator used: the run stopped, health OK);
//   - a SENSORS sample 1e12 us ahead (it stopped the estimator);
//   - a CMD_NOMINAL 1e12 us ahead (it disabled the safety process's
//     controller watchdog).
// The run must finish (no lockstep timeout), hold every limit on ground
// truth, count each rejection in the heartbeats under its name, answer
// nothing with a forged time, latch no fault, and afterwards the watchdog
// must still fire: with the controller killed, the safety process answers
// further states with its stale-input fallback.
//
// LCM port 7920 (this folder owns 7920-7939). It holds the launcher lock
// of the build folder, as the launched-stack tests do, so two stacks never
// share the 2 cores.
#include <gtest/gtest.h>
#include <signal.h>
#include <stdlib.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include "stewart/config/config_loader.h"
#include "stewart/force_command_t.hpp"
#include "stewart/health_t.hpp"
#include "stewart/node/lcm_handle.h"
#include "stewart/node/lcm_receiver.h"
#include "stewart/sensor_t.hpp"
#include "stewart/state_t.hpp"
#include "stewart/test_support/child_process.h"
#include "stewart/test_support/health_counter.h"
#include "stewart/test_support/recorded_run.h"
#include "stewart/test_support/stack_launch.h"

namespace stewart {
namespace {

constexpr int kPort = 7920;
constexpr double kDurationS = 6.0;
constexpr int64_t kForgedUtime = 8'000'000'000'000'000'000;
constexpr int64_t kAheadUs = 1'000'000'000'000;

/// What the test sees of the bus.
struct Bus {
  void OnSensor(const lcm::ReceiveBuffer*, const std::string&, const sensor_t* m) {
    if (m->utime < kAheadUs) last_sensor = *m;  // not the test's own forgery
  }
  void OnState(const lcm::ReceiveBuffer*, const std::string&, const state_t* m) {
    if (m->utime < kAheadUs) last_state = *m;
  }
  void OnNominal(const lcm::ReceiveBuffer*, const std::string&, const force_command_t* m) {
    if (m->sample_utime < kAheadUs) last_nominal = *m;
  }
  void OnSafe(const lcm::ReceiveBuffer*, const std::string&, const force_command_t* m) {
    safe.push_back(*m);
    if (m->sample_utime >= kAheadUs) ++safe_with_forged_time;
  }
  void OnHealth(const lcm::ReceiveBuffer*, const std::string&, const health_t* m) {
    health[m->name] = *m;
    if (m->fault_latched) latched[m->name] = m->latched_error;
  }
  sensor_t last_sensor{};
  state_t last_state{};
  force_command_t last_nominal{};
  std::vector<force_command_t> safe;
  int safe_with_forged_time = 0;
  std::map<std::string, health_t> health;
  std::map<std::string, std::string> latched;
};

TEST(ForgedTimeStack, LockstepRunSurvivesForgedTimesAndTheWatchdogStillFires) {
  test::LauncherLock lock;
  std::string folder = "/tmp/stewart_forged_time_XXXXXX";
  ASSERT_NE(mkdtemp(folder.data()), nullptr);
  const std::string log_path = folder + "/log.lcm";
  const StackConfig config = LoadStackConfig(DefaultConfigPath());
  const auto& ch = config.lcm.channels;
  const std::string url = PrivateLcmUrl(kPort);
  auto lcm = MakeLcm(url);
  LcmReceiver receiver(url);
  Bus bus;
  receiver.Subscribe(ch.sensors, &Bus::OnSensor, &bus);
  receiver.Subscribe(ch.state_estimate, &Bus::OnState, &bus);
  receiver.Subscribe(ch.command_nominal, &Bus::OnNominal, &bus);
  receiver.Subscribe(ch.command_safe, &Bus::OnSafe, &bus);
  receiver.Subscribe(ch.health, &Bus::OnHealth, &bus);
  const auto pump_until = [&](auto done, double timeout_s) {
    return test::PumpUntil(&receiver, done, timeout_s);
  };
  const auto pump_for = [&](double seconds) { pump_until([] { return false; }, seconds); };

  // Armed by the supervisor at start-up, as tools/launch.sh does in simulation.
  const std::string overlay = test::WriteAutoArmOverlay(folder);
  // As tools/launch.sh runs them: the loop on the last CPU, the logger and
  // this test on the others (docs/operations.md, "One CPU for the loop").
  const long cpus = sysconf(_SC_NPROCESSORS_ONLN);
  const std::vector<std::string> pin =
      cpus >= 2 && access("/usr/bin/taskset", X_OK) == 0
          ? std::vector<std::string>{"/usr/bin/taskset", "-c", std::to_string(cpus - 1)}
          : std::vector<std::string>{};
  const auto with = [&](std::vector<std::string> head) {
    head.insert(head.begin(), pin.begin(), pin.end());
    return test::WithStackFlags(std::move(head), url, overlay);
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
  test::ChildProcess plant(
      with({PLANT_SIM_PATH, "--mode", "lockstep", "--duration", std::to_string(kDurationS)}));
  ASSERT_TRUE(plant.started());

  // The attacks, one per simulated second from 1.5 s on.
  bool forged_state = false, forged_sensor = false, forged_nominal = false;
  const bool finished = pump_until(
      [&] {
        const int64_t t = bus.last_sensor.utime;
        if (!forged_state && t >= 1'500'000 && bus.last_state.utime > 0) {
          state_t s = bus.last_state;
          s.utime = s.sample_utime = kForgedUtime;
          lcm->publish(ch.state_estimate, &s);
          forged_state = true;
        }
        if (!forged_sensor && t >= 2'500'000) {
          sensor_t s = bus.last_sensor;
          s.utime = s.sample_utime = s.utime + kAheadUs;
          lcm->publish(ch.sensors, &s);
          forged_sensor = true;
        }
        if (!forged_nominal && t >= 3'500'000 && bus.last_nominal.sample_utime > 0) {
          force_command_t n = bus.last_nominal;
          n.utime = n.sample_utime = n.sample_utime + kAheadUs;
          lcm->publish(ch.command_nominal, &n);
          forged_nominal = true;
        }
        return !plant.running();
      },
      180.0);
  ASSERT_TRUE(finished) << "plant_sim did not finish within 180 s (simulated "
                        << 1e-6 * static_cast<double>(bus.last_sensor.utime) << " s)";
  EXPECT_EQ(plant.exit_code(), 0) << "3 is a lockstep timeout: the stack stopped answering";
  ASSERT_TRUE(forged_state && forged_sensor && forged_nominal);

  // Two more heartbeats of each, with every count in them. The pumping also
  // drains what this process had not read yet when plant_sim exited: on a
  // loaded machine the test can lag the bus by half a simulated second.
  pump_for(1.5);
  EXPECT_GE(bus.last_sensor.utime, static_cast<int64_t>((kDurationS - 0.01) * 1e6));
  EXPECT_EQ(bus.safe_with_forged_time, 0) << "a safe command answered a forged time";
  const health_t& estimator_health = bus.health["estimator"];
  const health_t& controller_health = bus.health["controller"];
  const health_t& safety_health = bus.health["safety"];
  EXPECT_EQ(test::HealthCounter(estimator_health, "rejected_sensor_time_implausible"), 1);
  EXPECT_EQ(test::HealthCounter(estimator_health, "rejected_command_time_implausible"), 0);
  EXPECT_EQ(test::HealthCounter(estimator_health, "rejected_non_increasing_time"), 0);
  EXPECT_EQ(test::HealthCounter(controller_health, "rejected_state_time_implausible"), 1);
  EXPECT_EQ(test::HealthCounter(controller_health, "rejected_state_time_not_increasing"), 0);
  EXPECT_EQ(test::HealthCounter(safety_health, "rejected_state_time_implausible"), 1);
  EXPECT_EQ(test::HealthCounter(safety_health, "rejected_nominal_time_implausible"), 1);
  EXPECT_EQ(test::HealthCounter(safety_health, "rejected_state_time_not_increasing"), 0);
  for (const auto& [name, h] : bus.health) {
    EXPECT_GE(h.rejected_inputs, test::HealthCounter(h, "rejected_state_time_implausible")) << name;
  }
  for (const auto& [name, error] : bus.latched) {
    ADD_FAILURE() << name << " latched a fault: " << error;
  }

  // The watchdog after the forged nominal command: the controller gone, the
  // test publishes further states (as the estimator would); from
  // safety.stale_age_s after the last nominal command on, each is answered
  // with the stale-input fallback.
  stack.controller.Stop(SIGKILL);
  const state_t last_state = bus.last_state;
  const int64_t last_nominal = bus.last_nominal.sample_utime;
  ASSERT_GT(last_nominal, 0);
  const size_t safe_before = bus.safe.size();
  const int64_t period_us = static_cast<int64_t>(1e6 / config.sensors.rate_hz);
  for (int k = 1; k <= 60; ++k) {
    state_t s = last_state;
    s.utime = s.sample_utime = last_state.utime + k * period_us;
    s.seq = last_state.seq + k;
    lcm->publish(ch.state_estimate, &s);
    pump_for(0.002);
  }
  pump_for(0.3);
  const int64_t stale_us = static_cast<int64_t>(config.safety.stale_age_s * 1e6);
  int fallbacks = 0;
  for (size_t i = safe_before; i < bus.safe.size(); ++i) {
    const force_command_t& c = bus.safe[i];
    if (c.sample_utime - last_nominal <= stale_us + period_us) continue;
    EXPECT_TRUE(c.flags & force_command_t::FLAG_STALE_INPUT) << c.sample_utime;
    ++fallbacks;
  }
  EXPECT_GE(fallbacks, 30) << "the watchdog did not answer the states after the stale age";

  // The limits, on the recorded ground truth.
  stack.logger.Stop(SIGTERM);
  const test::RecordedRun run = test::ReadRecordedRun(log_path, config);
  ASSERT_NE(run.Worst(), nullptr);
  std::printf("[forged time] %s; %d watchdog fallbacks\n", test::Describe(run).c_str(), fallbacks);
  // The logger is not pinned: on a loaded machine it can miss a few percent
  // of a lockstep run (docs/operations.md, "Logging"); the limits are
  // checked on every sample it has.
  EXPECT_GE(static_cast<double>(run.truth_samples), 0.9 * kDurationS * config.sensors.rate_hz);
  test::ExpectWithinLimits(run);
  // Armed and under way: the paper scenario's x step (0.1 m within 6 s).
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
