// An attacker on CMD_NOMINAL against the whole loop in one process: the
// controller's nominal replaced by +-1e6 N per leg, once a second and in a
// stream of 100 samples, while the plant is heavier than the model and
// carries a payload off-centre. The limits hold on ground truth (within the
// stated tolerance) with the per-period bound, and not without it (the before:
// docs/safety.md "One sample period").
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "stewart/config/config_loader.h"
#include "stewart/config/default_config.h"
#include "stewart/config/scenario_loader.h"
#include "stewart/config/truth_loader.h"
#include "stewart/controller/scenario.h"
#include "stewart/stack/closed_loop.h"

namespace stewart {
namespace {

constexpr double kLimitTolerance = 1e-3;  // m and m/s, docs/safety.md "Tolerance"

// Within the bounds docs/safety.md states for the model error.
constexpr char kHeavierWithPayload[] = R"(
platform:
  mass_kg: 0.75
  payload: {mass_kg: 0.2, position_m: [0.05, -0.03, 0.03]}
actuators: {viscous_friction_nspm: 4.0}
)";

Vector6d Alternating() { return (Vector6d() << 1e6, -1e6, 1e6, -1e6, 1e6, -1e6).finished(); }

ClosedLoopSummary RunAttacked(bool bound, const std::function<void(long, Vector6d*)>& forge) {
  StackConfig config = DefaultStackConfig();
  if (!bound) config.safety.sample_period_s = 0.0;
  const Scenario scenario = LoadScenario(ResolveScenarioPath("paper"));
  ClosedLoopOptions options;
  options.duration_s = 12.0;
  options.seed = 4;
  options.truth =
      ParsePlantTruth(config, LoadYamlFile(DefaultConfigPath()), YAML::Load(kHeavierWithPayload));
  options.forge_nominal = forge;
  return RunClosedLoop(config, scenario, options, nullptr);
}

// Once a second, one sample's nominal, alternating in sign.
void OncePerSecond(long tick, Vector6d* force_n) {
  if (tick > 2000 && tick % 1000 == 0)
    *force_n = (tick / 1000) % 2 ? Alternating() : -Alternating();
}

// 100 consecutive samples from t = 5 s, each a different sign pattern.
void Stream(long tick, Vector6d* force_n) {
  if (tick < 5000 || tick >= 5100) return;
  for (int j = 0; j < 6; ++j) (*force_n)(j) = ((tick >> j) & 1) ? 1e6 : -1e6;
}

TEST(SampledData, SingleMillionNewtonNominalsHoldTheLimitsOnTruth) {
  const ClosedLoopSummary with = RunAttacked(true, OncePerSecond);
  ASSERT_TRUE(with.completed) << with.failure;
  EXPECT_LE(with.max_limit_excess, kLimitTolerance) << with.max_limit_excess_name;
  const ClosedLoopSummary without = RunAttacked(false, OncePerSecond);
  EXPECT_GT(without.max_limit_excess, 5 * kLimitTolerance) << without.failure;
  std::printf("once a second: worst excess %.3g (%s) bounded, %.3g (%s) unbounded\n",
              with.max_limit_excess, with.max_limit_excess_name.c_str(), without.max_limit_excess,
              without.max_limit_excess_name.c_str());
}

TEST(SampledData, AStreamOfMillionNewtonNominalsHoldsTheLimitsOnTruth) {
  const ClosedLoopSummary with = RunAttacked(true, Stream);
  ASSERT_TRUE(with.completed) << with.failure;
  EXPECT_LE(with.max_limit_excess, kLimitTolerance) << with.max_limit_excess_name;
  const ClosedLoopSummary without = RunAttacked(false, Stream);
  EXPECT_GT(without.max_limit_excess, 10 * kLimitTolerance) << without.failure;
  std::printf("stream of 100: worst excess %.3g (%s) bounded, %.3g (%s) unbounded\n",
              with.max_limit_excess, with.max_limit_excess_name.c_str(), without.max_limit_excess,
              without.max_limit_excess_name.c_str());
}

}  // namespace
}  // namespace stewart
