#include "stewart/safety/constraint_set.h"

#include <gtest/gtest.h>

#include <stdexcept>

#include "safety_test_support.h"

namespace stewart::safety::test {
namespace {

TEST(ConstraintSet, DefaultConfigIsThePapersUpperLimitsAndTheLegStrokes) {
  const ConstraintSet c = BuildConstraintSet(DefaultConfig().platform, DefaultConfig().safety);
  // x, y, z upper, then a lower and an upper stroke barrier per leg.
  EXPECT_EQ(c.num_position, 3 + 2 * kNumLegs);
  EXPECT_EQ(c.position[3].source, PositionSource::kLegLength);
  // The three velocity limits, then one recovery barrier per position limit.
  EXPECT_EQ(c.num_velocity, 6);
  EXPECT_EQ(c.position[2].name, "z_upper");
  EXPECT_EQ(c.velocity[2].name, "zd_upper");
  EXPECT_EQ(c.velocity[2].alpha_v, 2.0);
  EXPECT_EQ(c.velocity[2].recovery_of, -1);
  EXPECT_EQ(c.velocity[5].name, "z_upper_recovery");
  EXPECT_EQ(c.velocity[5].recovery_of, 2);
  EXPECT_EQ(c.velocity[5].axis, 2);
  EXPECT_EQ(c.velocity[5].sign, -1.0);
  EXPECT_TRUE(c.has_recovery);
}

TEST(ConstraintSet, RecoveryGainZeroLeavesTheRecoveryBarriersOut) {
  SafetyConfig s = DefaultConfig().safety;
  s.recovery_gain_per_s = 0.0;
  const ConstraintSet c = BuildConstraintSet(DefaultConfig().platform, s);
  EXPECT_EQ(c.num_velocity, 3);
  EXPECT_FALSE(c.has_recovery);
}

TEST(ConstraintSet, RichConfigHasEveryKind) {
  const ConstraintSet c = BuildConstraintSet(DefaultConfig().platform, RichSafetyConfig());
  EXPECT_EQ(c.num_position, 8 + 12);
  // 8 velocity limits and a recovery barrier per axis limit (not the legs').
  EXPECT_EQ(c.num_velocity, 8 + 8);
  EXPECT_EQ(c.position[0].name, "x_lower");
  EXPECT_EQ(c.position[8].name, "leg0_lower");
  EXPECT_EQ(c.position[8].source, PositionSource::kLegLength);
  EXPECT_DOUBLE_EQ(c.position[9].limit, DefaultConfig().platform.leg_max_length_m - 0.005);
}

TEST(ConstraintSet, TooManyLimitsAreRejected) {
  SafetyConfig s = RichSafetyConfig();
  for (int i = 0; i < 3; ++i)
    s.position_limits.insert(s.position_limits.end(), s.position_limits.begin(),
                             s.position_limits.begin() + 4);
  EXPECT_THROW(BuildConstraintSet(DefaultConfig().platform, s), std::invalid_argument);
}

TEST(ConstraintSet, QpVariantNeedsAReferenceSolver) {
  SafetyConfig s = RichSafetyConfig();
  s.variant = SafetyVariant::kQpReference;
  EXPECT_THROW(SafetyFilter(DefaultConfig().platform, s, DefaultConfig().actuators),
               std::invalid_argument);
}

}  // namespace
}  // namespace stewart::safety::test
