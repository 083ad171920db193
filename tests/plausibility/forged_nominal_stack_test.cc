// A forger on CMD_NOMINAL (which is not authenticated: any process may
// propose a nominal, only the filter's output moves the platform) against a
// lockstep run of the real processes on a private URL. Each forgery is timed
// for the next sample, so the safety process filters it before the
// controller's own: +-1e6 N per leg, once a second and then in a stream of
// 100 consecutive samples, against a plant heavier than the model with a
// payload. Every limit must hold on the recorded ground
// truth, every answer to a forgery must carry FLAG_NOMINAL_BOUNDED, and the
// safety heartbeat must count them (docs/safety.md "One sample period").
// With the bound switched off (the before), the first forgery makes the
// filter command the force limit and plant_sim's guard has to stop the run.
//
// LCM port 7922 (this folder owns 7920-7939). It holds the launcher lock
// of the build folder, as the launched-stack tests do.
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "stewart/config/config_loader.h"
#include "stewart/force_command_t.hpp"
#include "stewart/health_t.hpp"
#include "stewart/node/lcm_handle.h"
#include "stewart/node/lcm_receiver.h"
#include "stewart/state_t.hpp"
#include "stewart/test_support/child_process.h"
#include "stewart/test_support/health_counter.h"
#include "stewart/test_support/recorded_run.h"
#include "stewart/test_support/stack_launch.h"

namespace stewart {
namespace {

constexpr int kPort = 7922;
constexpr double kDurationS = 8.0;

struct Bus {
  void OnState(const lcm::ReceiveBuffer*, const std::string&, const state_t* m) { last_state = *m; }
  void OnSafe(const lcm::ReceiveBuffer*, const std::string&, const force_command_t* m) {
    safe[m->sample_utime] = *m;
  }
  void OnHealth(const lcm::ReceiveBuffer*, const std::string&, const health_t* m) {
    health[m->name] = *m;
  }
  state_t last_state{};
  std::map<int64_t, force_command_t> safe;
  std::map<std::string, health_t> health;
};

// With the per-period bound as shipped, and (the before) switched off.
class ForgedNominalStack : public ::testing::TestWithParam<bool> {};

TEST_P(ForgedNominalStack, MillionNewtonNominalsForTheNextSample) {
  const bool bound = GetParam();
  test::LauncherLock lock;
  std::string folder = "/tmp/stewart_forged_nominal_XXXXXX";
  ASSERT_NE(mkdtemp(folder.data()), nullptr);
  const std::string log_path = folder + "/log.lcm";
  const StackConfig config = LoadStackConfig(DefaultConfigPath());
  const auto& ch = config.lcm.channels;
  const std::string url = PrivateLcmUrl(kPort);
  auto lcm = MakeLcm(url);
  LcmReceiver receiver(url);
  Bus bus;
  receiver.Subscribe(ch.state_estimate, &Bus::OnState, &bus);
  receiver.Subscribe(ch.command_safe, &Bus::OnSafe, &bus);
  receiver.Subscribe(ch.health, &Bus::OnHealth, &bus);
  const auto pump_until = [&](auto done, double timeout_s) {
    return test::PumpUntil(&receiver, done, timeout_s);
  };

  const std::string overlay =
      test::WriteAutoArmOverlay(folder, bound ? ""
                                              : "safety:\n  per_period_velocity_step_mps: 0.0\n"
                                                "  per_period_angular_step_radps: 0.0\n");
  const auto with = [&](std::vector<std::string> argv) {
    return test::WithStackFlags(std::move(argv), url, overlay);
  };
  // The plant is not the model the stack uses: 20 % heavier, a 0.2 kg payload
  // off-centre, more leg friction (within docs/safety.md's stated bounds).
  const std::string truth = folder + "/truth.yaml";
  std::ofstream(truth) << "platform:\n  mass_kg: 0.75\n"
                          "  payload: {mass_kg: 0.2, position_m: [0.05, -0.03, 0.03]}\n"
                          "actuators: {viscous_friction_nspm: 4.0}\n";
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
  test::ChildProcess plant(with({PLANT_SIM_PATH, "--mode", "lockstep", "--duration",
                                 std::to_string(kDurationS), "--truth", truth}));
  ASSERT_TRUE(plant.started());

  // Once a second from 2 s, then every sample from 5.0 s for 100 samples;
  // each for the sample after the newest state.
  const int64_t period_us = static_cast<int64_t>(1e6 / config.sensors.rate_hz);
  std::set<int64_t> forged_samples;
  int64_t last_forged_for = 0;
  const bool finished = pump_until(
      [&] {
        const int64_t t = bus.last_state.utime;
        const bool once = t >= 2'000'000 && t < 5'000'000 && t % 1'000'000 == 0;
        const bool stream = t >= 5'000'000 && t < 5'000'000 + 100 * period_us;
        const int64_t next = t + period_us;
        if ((once || stream) && next > last_forged_for) {
          force_command_t n{};
          n.utime = n.sample_utime = next;
          for (int j = 0; j < 6; ++j) n.force_n[j] = ((next / period_us) >> j) & 1 ? 1e6 : -1e6;
          lcm->publish(ch.command_nominal, &n);
          forged_samples.insert(next);
          last_forged_for = next;
        }
        return !plant.running();
      },
      180.0);
  ASSERT_TRUE(finished) << "plant_sim did not finish within 180 s";
  EXPECT_EQ(plant.exit_code(), 0) << "3 is a lockstep timeout: the stack stopped answering";
  pump_until([] { return false; }, 1.5);  // the last heartbeats

  // How many forgeries the safety process filtered before the controller's
  // nominal for the same sample: each answer to one is bounded and flagged.
  int answered_forgeries = 0;
  for (const int64_t sample : forged_samples) {
    const auto it = bus.safe.find(sample);
    if (it == bus.safe.end()) continue;
    if (it->second.flags & force_command_t::FLAG_NOMINAL_BOUNDED) ++answered_forgeries;
    for (int j = 0; j < 6; ++j) {
      EXPECT_LE(std::abs(it->second.force_n[j]), config.actuators.force_limit_n + 1e-9);
    }
  }
  if (bound) {
    EXPECT_GE(answered_forgeries, 50) << "of " << forged_samples.size() << " forgeries";
    EXPECT_GE(test::HealthCounter(bus.health["safety"], "nominal_bounded"), answered_forgeries);
  } else {
    EXPECT_EQ(answered_forgeries, 0);
  }

  stack.logger.Stop(SIGTERM);
  const test::RecordedRun run = test::ReadRecordedRun(log_path, config);
  ASSERT_NE(run.Worst(), nullptr);
  std::printf("[forged nominal] %zu forgeries, %d answered bounded; %s\n", forged_samples.size(),
              answered_forgeries, test::Describe(run).c_str());
  EXPECT_GE(static_cast<double>(run.truth_samples), 0.9 * kDurationS * config.sensors.rate_hz);
  const int64_t guard_trips = test::HealthCounter(bus.health["plant_sim"], "guard_trips");
  ASSERT_TRUE(bus.health.count("plant_sim"));
  if (bound) {
    // The forgeries change nothing the filter would not allow: every limit
    // held, the guard never needed, the scenario's x step under way.
    test::ExpectWithinLimits(run);
    EXPECT_EQ(guard_trips, 0);
    EXPECT_GT(run.max_x, 0.05) << "the platform did not move";
  } else {
    // The before: the filter passes the force limit (100 N per leg) at the
    // first forgery, and only plant_sim's last-line guard (20 N) stops the
    // platform, for the rest of the run.
    EXPECT_GE(guard_trips, 1);
    EXPECT_LT(run.max_x, 0.05);
  }
  if (!::testing::Test::HasFailure()) {
    std::error_code ignored;
    std::filesystem::remove_all(folder, ignored);
  } else {
    std::printf("run folder kept: %s\n", folder.c_str());
  }
}

INSTANTIATE_TEST_SUITE_P(PerPeriodBound, ForgedNominalStack, ::testing::Bool(),
                         [](const ::testing::TestParamInfo<bool>& param) {
                           return param.param ? "Bounded" : "UnboundedBefore";
                         });

}  // namespace
}  // namespace stewart
