// A broken precondition in safety/ is a programmer error: STEWART_CHECK
// throws std::logic_error rather than let the step write past an array.
#include <gtest/gtest.h>

#include <stdexcept>

#include "safety_test_support.h"
#include "stewart/safety/barriers.h"
#include "stewart/safety/log_sum_exp.h"
#include "stewart/safety/projection_qp.h"

namespace stewart::safety::test {
namespace {

TEST(Preconditions, LogSumExpNeedsATerm) {
  double alpha_h[1] = {1.0};
  double weights[1] = {0.0};
  EXPECT_THROW(ComposeLogSumExp(alpha_h, 0, 1.0, weights), std::logic_error);
  EXPECT_NO_THROW(ComposeLogSumExp(alpha_h, 1, 1.0, weights));
}

TEST(Preconditions, ForceLimitRowsNeedRoomInTheQp) {
  ProjectionQpN<2 * kNumLegs + 1> qp;
  qp.m = 2;
  EXPECT_THROW(AppendForceLimitRows(Matrix6d::Identity(), 1.0, &qp), std::logic_error);
  qp.m = 1;
  EXPECT_NO_THROW(AppendForceLimitRows(Matrix6d::Identity(), 1.0, &qp));
  EXPECT_EQ(qp.m, 2 * kNumLegs + 1);
}

TEST(Preconditions, ConditionRowNeedsRoomInTheQp) {
  ProjectionQpN<1> qp;
  qp.m = 1;
  EXPECT_THROW(AppendConditionRow(-1.0, Vector6d::Unit(0), &qp), std::logic_error);
}

TEST(Preconditions, ProjectionQpRowCountWithinCapacity) {
  ProjectionQp qp;
  qp.m = kMaxQpRows + 1;
  EXPECT_THROW(SolveProjectionQp(qp), std::logic_error);
  qp.m = -1;
  EXPECT_THROW(SolveProjectionQp(qp), std::logic_error);
}

TEST(Preconditions, BarriersWithinTheirArrays) {
  const SafetyFilter filter = MakeRichFilter();
  ConstraintSet c = filter.constraints();
  const Vector6d q = DefaultConfig().home_pose;
  const DynamicsTerms t = EvaluateDynamics(DefaultConfig().platform, q, Vector6d::Zero());
  BarrierEvaluation e;
  EXPECT_NO_THROW(EvaluateBarriers(c, q, Vector6d::Zero(), t, HoverForce(q), &e));
  c.num_velocity = kMaxVelocityBarriers + 1;
  EXPECT_THROW(EvaluateBarriers(c, q, Vector6d::Zero(), t, HoverForce(q), &e), std::logic_error);
  c.num_velocity = 0;
  c.num_position = -1;
  EXPECT_THROW(EvaluateBarriers(c, q, Vector6d::Zero(), t, HoverForce(q), &e), std::logic_error);
}

// Bad user input is not a programmer error: InputError names the config key.
TEST(Preconditions, UnusableConfigNamesItsKey) {
  SafetyConfig s = RichSafetyConfig();
  s.stop_time_s = 0.0;
  try {
    SafetyFilter(DefaultConfig().platform, s, DefaultConfig().actuators);
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.key(), "safety.stop_time_s");
  }
  s = RichSafetyConfig();
  s.k_velocity = -1.0;
  EXPECT_THROW(BuildConstraintSet(DefaultConfig().platform, s), InputError);
}

}  // namespace
}  // namespace stewart::safety::test
