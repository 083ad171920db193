#pragma once
// One campaign run replayed in process from what `stewart_campaign --rerun
// DIR --row R --emit-truth` wrote into config/truths/: the truth
// (`name`.yaml), its setpoints (`name`-scenario.yaml, or one of
// config/scenarios/ by name for the fixed scenarios) and the run's seed.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
#include <string>

#include "stewart/config/scenario_loader.h"
#include "stewart/config/truth_loader.h"
#include "stewart/controller/scenario.h"
#include "stewart/stack/closed_loop.h"

namespace stewart {
namespace test {

inline ClosedLoopSummary RunCampaignTruth(const StackConfig& config, const std::string& name,
                                          uint64_t seed, const std::string& scenario_name = "") {
  const std::string truths = std::string(STEWART_SOURCE_DIR) + "/config/truths/";
  const Scenario scenario =
      LoadScenario(scenario_name.empty() ? truths + name + "-scenario.yaml"
                                         : ResolveScenarioPath(scenario_name));
  ClosedLoopOptions options;
  options.seed = seed;
  options.truth = LoadPlantTruth(config, truths + name + ".yaml");
  const ClosedLoopSummary s = RunClosedLoop(config, scenario, options, nullptr);
  std::printf("[%s] worst excess %.2f mm(/s) (%s), restarts %ld, rms velocity error %.2f mm/s\n",
              name.c_str(), s.max_limit_excess * 1e3, s.max_limit_excess_name.c_str(),
              static_cast<long>(s.estimator_reinits), s.rms_qd_error * 1e3);
  return s;
}

constexpr double kLimitTolerance = 1e-3;  // m and m/s, docs/safety.md "Tolerance"

struct WithoutAndWith {
  ClosedLoopSummary without;
  ClosedLoopSummary with;
};

/// Runs `run` with `without` and with `with`: the first must break a limit
/// beyond the tolerance, the second hold every limit within it, without a
/// restart of the estimate. Both summaries for further checks.
template <class Run>
WithoutAndWith ExpectHoldsOnlyWith(const StackConfig& without, const StackConfig& with, Run run) {
  WithoutAndWith r{run(without), run(with)};
  EXPECT_TRUE(r.without.completed);
  EXPECT_GT(r.without.max_limit_excess, kLimitTolerance);
  EXPECT_TRUE(r.with.completed);
  EXPECT_LE(r.with.max_limit_excess, kLimitTolerance) << r.with.max_limit_excess_name;
  EXPECT_EQ(r.with.estimator_reinits, 0);
  return r;
}

}  // namespace test
}  // namespace stewart
