// A platform that is not the model, in process, where its dry friction
// flips: the bounds' random campaign run 15 (config/truths/
// bounds-dry-friction-reversal.yaml and its setpoints), whose legs carry up
// to 0.29 N of dry friction the model lacks. At 36.13 s a setpoint step
// reverses legs that were creeping; the friction's torque flips with them
// and the model error d must follow within samples. Without the force-change
// allowance (estimator.disturbance.force_change_std) the gyro was gated two
// samples of three for 150 ms, the velocity estimate lagged the truth by
// 5 mm/s and xd went 2.9 mm/s past its limit.
//
// And where the allowance fed back: the bounds' random campaign run 409
// (config/truths/bounds-force-change-loop.yaml and its setpoints). Against
// the x limit with both of its conditions active, the filter's command
// changed, the allowance widened d's std in proportion, the robust margin
// grew with the std and the command changed more: 11 N in one tick, zd
// 30 mm/s past its limit. Each leg's change counts at most
// estimator.disturbance.force_change_cap_n.
#include <gtest/gtest.h>

#include <cstdio>
#include <limits>
#include <string>

#include "campaign_truth.h"
#include "stewart/config/default_config.h"

namespace stewart {
namespace {

using test::kLimitTolerance;

/// The run with the friction-flip allowance off: these runs show what the
/// force-change allowance and its cap do on their own. (With the flip
/// allowance on, both runs hold even without the force-change allowance or
/// its cap: -2.2 and -1.2 mm/s; docs/estimator.md, "Friction-flip
/// allowance".)
ClosedLoopSummary RunCampaignTruth(StackConfig config, const std::string& name, uint64_t seed) {
  config.estimator.disturbance_friction_flip_std_n = 0.0;
  std::printf(
      "[force change] allowance std %.2f, cap %g N, friction-flip allowance off, d re-opened "
      "after %d samples:\n",
      config.estimator.disturbance_force_change_std,
      config.estimator.disturbance_force_change_cap_n,
      config.estimator.disturbance_jump_after_samples);
  return test::RunCampaignTruth(config, name, seed);
}

ClosedLoopSummary RunReversal(const StackConfig& config) {
  return RunCampaignTruth(config, "bounds-dry-friction-reversal", 4140594655u);
}

TEST(ForceChange, DryFrictionReversedByASetpointStepKeepsTheVelocityLimits) {
  StackConfig without_config = DefaultStackConfig();
  without_config.estimator.disturbance_force_change_std = 0.0;
  test::ExpectHoldsOnlyWith(without_config, DefaultStackConfig(), RunReversal);
}

// The loop ran away while d re-opened only after 20 gated accelerometer
// samples (the value the run was found with): 10 mm/s past the limit; with
// 5 (shipped until 2026-12-06) the re-opening cut it short, but the run
// still broke the tolerance without the cap. With the shipped 2 (or 3,
// docs/estimator.md, "Steps") the re-opening alone holds this run; the cap
// stays as the bound on the loop's gain.
TEST(ForceChange, TheAllowanceDoesNotFeedTheFiltersMarginBack) {
  StackConfig uncapped_config = DefaultStackConfig();
  ASSERT_LT(uncapped_config.estimator.disturbance_force_change_cap_n, 10.0);
  ASSERT_LT(uncapped_config.estimator.disturbance_jump_after_samples, 5);
  uncapped_config.estimator.disturbance_force_change_cap_n =
      std::numeric_limits<double>::infinity();
  const ClosedLoopSummary uncapped_shipped =
      RunCampaignTruth(uncapped_config, "bounds-force-change-loop", 1429968929u);
  ASSERT_TRUE(uncapped_shipped.completed);
  EXPECT_LE(uncapped_shipped.max_limit_excess, kLimitTolerance)
      << uncapped_shipped.max_limit_excess_name;
  // Uncapped with 5 and 20 samples this run went 3.4 and 14.4 mm/s past zd
  // until the filter's QP skipped its re-solve where it moves the answer by
  // rounding only (docs/performance.md): the loop needs this trajectory to
  // the last bit, and since then it holds there too (-1.65 mm/s with both),
  // so only the configurations the stack ships with are asserted here.
  StackConfig capped_config = DefaultStackConfig();
  capped_config.estimator.disturbance_jump_after_samples = 5;
  const ClosedLoopSummary capped_at_5 =
      RunCampaignTruth(capped_config, "bounds-force-change-loop", 1429968929u);
  ASSERT_TRUE(capped_at_5.completed);
  EXPECT_LE(capped_at_5.max_limit_excess, kLimitTolerance) << capped_at_5.max_limit_excess_name;
  const ClosedLoopSummary capped =
      RunCampaignTruth(DefaultStackConfig(), "bounds-force-change-loop", 1429968929u);
  ASSERT_TRUE(capped.completed);
  EXPECT_LE(capped.max_limit_excess, kLimitTolerance) << capped.max_limit_excess_name;
  EXPECT_EQ(capped.estimator_reinits, 0);
}

}  // namespace
}  // namespace stewart
