// A platform that is not the model, in process, where its dry friction
// flips: the bounds' random campaign run 15 (config/truths/
// bounds-dry-friction-reversal.yaml and its setpoints), whose legs carry up
// to 0.29 N of dry friction the model lacks. At 36.13 s a setpoint step
// reverses legs that were creeping; the friction's torque flips with them
// and the model error d must follow within samples. Without the force-change
// allowance (estimator.disturbance.force_change_std) the gyro was gated two
// samples of three for 150 ms, the velocity estimate lagged the truth by
// 5 mm/s and xd went 2.9 mm/s past its limit.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "stewart/config/default_config.h"
#include "stewart/config/scenario_loader.h"
#include "stewart/config/truth_loader.h"
#include "stewart/controller/scenario.h"
#include "stewart/stack/closed_loop.h"

namespace stewart {
namespace {

constexpr double kLimitTolerance = 1e-3;  // m and m/s, docs/safety.md "Tolerance"

ClosedLoopSummary RunReversal(const StackConfig& config) {
  const std::string truths = std::string(STEWART_SOURCE_DIR) + "/config/truths/";
  const Scenario scenario = LoadScenario(truths + "bounds-dry-friction-reversal-scenario.yaml");
  ClosedLoopOptions options;
  options.seed = 4140594655u;  // the campaign run's
  options.truth = LoadPlantTruth(config, truths + "bounds-dry-friction-reversal.yaml");
  const ClosedLoopSummary s = RunClosedLoop(config, scenario, options, nullptr);
  std::printf(
      "[force change] allowance std %.2f: worst excess %.2f mm(/s) (%s), restarts %ld, "
      "rms velocity error %.2f mm/s\n",
      config.estimator.disturbance_force_change_std, s.max_limit_excess * 1e3,
      s.max_limit_excess_name.c_str(), static_cast<long>(s.estimator_reinits),
      s.rms_qd_error * 1e3);
  return s;
}

TEST(ForceChange, DryFrictionReversedByASetpointStepKeepsTheVelocityLimits) {
  StackConfig without_config = DefaultStackConfig();
  without_config.estimator.disturbance_force_change_std = 0.0;
  const ClosedLoopSummary without = RunReversal(without_config);
  ASSERT_TRUE(without.completed);
  EXPECT_GT(without.max_limit_excess, kLimitTolerance);
  const ClosedLoopSummary with = RunReversal(DefaultStackConfig());
  ASSERT_TRUE(with.completed);
  EXPECT_LE(with.max_limit_excess, kLimitTolerance) << with.max_limit_excess_name;
  EXPECT_EQ(with.estimator_reinits, 0);
}

}  // namespace
}  // namespace stewart
