// Killing the controller mid-run, with the real processes (plant_sim in real
// time, estimator, controller, safety) on a private URL: the safety process
// must answer every state with its flagged fallback once no nominal command
// newer than safety.stale_age_s (in state time) exists, and the plant must
// keep receiving commands (no command timeout): the platform is held, not
// left to its own devices. LCM port 7822 (this folder owns 7820-7829).
#include <gtest/gtest.h>
#include <signal.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <string>
#include <vector>

#include "stewart/config/config_loader.h"
#include "stewart/force_command_t.hpp"
#include "stewart/node/lcm_handle.h"
#include "stewart/test_support/child_process.h"
#include "stewart/test_support/stack_launch.h"

namespace stewart {
namespace {

constexpr int kPort = 7822;

struct Sink {
  void OnSafe(const lcm::ReceiveBuffer*, const std::string&, const force_command_t* msg) {
    safe.push_back(*msg);
  }
  void OnNominal(const lcm::ReceiveBuffer*, const std::string&, const force_command_t* msg) {
    newest_nominal_sample_utime = std::max(newest_nominal_sample_utime, msg->sample_utime);
  }
  std::vector<force_command_t> safe;
  int64_t newest_nominal_sample_utime = -1;
};

bool IsFallback(const force_command_t& c) {
  return (c.flags & force_command_t::FLAG_FALLBACK) != 0;
}

TEST(ControllerKill, SafetyFallsBackWithinTheStaleAgeAndThePlantKeepsGettingCommands) {
  test::LauncherLock lock;  // a real-time stack: no other stack or browser beside it
  const StackConfig config = LoadStackConfig(DefaultConfigPath());
  const std::string url = PrivateLcmUrl(kPort);
  auto lcm = MakeLcm(url);
  Sink sink;
  lcm->subscribe(config.lcm.channels.command_safe, &Sink::OnSafe, &sink)->setQueueCapacity(100000);
  lcm->subscribe(config.lcm.channels.command_nominal, &Sink::OnNominal, &sink)
      ->setQueueCapacity(100000);
  // A simulation: the supervisor arms by itself (as tools/launch.sh has it).
  const std::string overlay = ::testing::TempDir() + "controller_kill_overlay.yaml";
  std::ofstream(overlay) << "supervisor:\n  auto_arm: true\n";
  const std::vector<std::string> common = {"--lcm-url", url,           "--overlay",
                                           overlay,     "--log-level", "warn"};
  auto with = [&](std::vector<std::string> head) {
    head.insert(head.end(), common.begin(), common.end());
    return head;
  };
  test::ChildProcess safety(with({SAFETY_PATH}));
  test::ChildProcess controller(with({CONTROLLER_PATH, "--scenario", "paper"}));
  test::ChildProcess estimator(with({ESTIMATOR_PATH}));
  test::ChildProcess plant(with({PLANT_SIM_PATH, "--mode", "realtime"}));
  ASSERT_TRUE(safety.started() && controller.started() && estimator.started() && plant.started());

  auto pump_for = [&](double seconds) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (std::chrono::steady_clock::now() < end) lcm->handleTimeout(10);
  };
  // Running normally: the last 200 safe commands are filtered, not fallbacks.
  pump_for(2.0);
  ASSERT_GT(sink.safe.size(), 1000u) << "the stack did not come up";
  const size_t n = sink.safe.size();
  ASSERT_TRUE(std::none_of(sink.safe.end() - 200, sink.safe.end(), IsFallback))
      << "the stack was not running normally before the kill";

  controller.Stop(SIGKILL);
  pump_for(1.0);
  const int64_t last_nominal = sink.newest_nominal_sample_utime;
  ASSERT_GT(last_nominal, 0);
  const int64_t stale_us = static_cast<int64_t>(config.safety.stale_age_s * 1e6);
  const int64_t period_us = static_cast<int64_t>(1e6 / config.sensors.rate_hz);

  // Commands derived from states after the last nominal one.
  std::vector<force_command_t> after;
  for (size_t i = n; i < sink.safe.size(); ++i) {
    if (sink.safe[i].sample_utime > last_nominal) after.push_back(sink.safe[i]);
  }
  ASSERT_GT(after.size(), 500u) << "commands stopped after the kill";
  const auto first_fallback = std::find_if(after.begin(), after.end(), IsFallback);
  ASSERT_NE(first_fallback, after.end()) << "no fallback after the controller died";
  // Within the stale age (state time) plus one sample of slack.
  EXPECT_LE(first_fallback->sample_utime - last_nominal, stale_us + period_us);
  EXPECT_TRUE(first_fallback->flags & force_command_t::FLAG_STALE_INPUT);
  // From then on every state is answered, by a flagged, finite fallback.
  int64_t previous = first_fallback->sample_utime;
  for (auto it = first_fallback; it != after.end(); ++it) {
    EXPECT_TRUE(IsFallback(*it)) << "non-fallback at " << it->sample_utime;
    for (double f : it->force_n) EXPECT_TRUE(std::isfinite(f));
    EXPECT_LE(it->sample_utime - previous, 5 * period_us) << "a gap in the commands";
    previous = it->sample_utime;
  }
  std::printf(
      "[kill] last nominal %lld us, first fallback +%lld us (stale age %lld us), %zu "
      "fallback commands in 1 s\n",
      static_cast<long long>(last_nominal),
      static_cast<long long>(first_fallback->sample_utime - last_nominal),
      static_cast<long long>(stale_us), static_cast<size_t>(after.end() - first_fallback));
}

}  // namespace
}  // namespace stewart
