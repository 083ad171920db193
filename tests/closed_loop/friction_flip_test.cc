// Dry friction flipping where legs reverse, in process: the bounds' random
// campaign run 440 (config/truths/bounds-dry-friction-flip.yaml and its
// setpoints), 0.21-0.30 N of dry friction on three legs that the model
// lacks. Where a command change reverses legs the friction's share of d
// changes by up to 0.6 N per leg within samples; the force-change
// allowance, in proportion to the command's change, opened d too little and
// the velocity estimate lagged the truth. With the friction-flip allowance
// (estimator.disturbance.friction_flip_std_n) d's covariance opens along
// each reversing leg's column of H.
#include <gtest/gtest.h>

#include <cstdio>

#include "campaign_truth.h"
#include "stewart/config/default_config.h"

namespace stewart {
namespace {

ClosedLoopSummary RunFlip(const StackConfig& config) {
  std::printf("[friction flip] allowance std %.2f N, band %.1f mm/s:\n",
              config.estimator.disturbance_friction_flip_std_n,
              1e3 * config.estimator.disturbance_friction_flip_speed_mps);
  return test::RunCampaignTruth(config, "bounds-dry-friction-flip", 1827262097u);
}

TEST(FrictionFlip, LegsReversedThroughDryFrictionKeepTheVelocityLimits) {
  StackConfig without_config = DefaultStackConfig();
  ASSERT_GT(without_config.estimator.disturbance_friction_flip_std_n, 0.0);
  without_config.estimator.disturbance_friction_flip_std_n = 0.0;
  test::ExpectHoldsOnlyWith(without_config, DefaultStackConfig(), RunFlip);
}

}  // namespace
}  // namespace stewart
