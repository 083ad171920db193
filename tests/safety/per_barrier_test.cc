// Variant closed_form with check_each_barrier (docs/safety.md, "Each barrier
// checked"): the composed closed form answers wherever its answer meets every
// barrier's own condition; elsewhere the un-composed QP answers, flagged.
#include <gtest/gtest.h>

#include <random>

#include "safety_test_support.h"

namespace stewart::safety::test {
namespace {

// The rich config with the shipped LSE sharpness and class-K rate, where the
// composed velocity condition trades one barrier against another.
SafetyConfig CheckedConfig(bool check, SafetyVariant variant = SafetyVariant::kClosedForm) {
  SafetyConfig s = RichSafetyConfig();
  const SafetyConfig& shipped = DefaultConfig().safety;
  s.k_velocity = shipped.k_velocity;
  s.velocity_rate_per_s = shipped.velocity_rate_per_s;
  s.velocity_robust_margin_mps2 = shipped.velocity_robust_margin_mps2;
  s.check_each_barrier = check;
  s.variant = variant;
  return s;
}

// The smallest slack over every barrier's own condition at F, in units of
// its unit-normal row (uncomposed_qp.h): negative when F breaks one.
double WorstOwnConditionSlack(SafetyFilter& filter, const FilterInput& x,
                              const SafetyDiagnostics& d, const Vector6d& f) {
  const Matrix6d map = filter.MetricMap(x.terms);
  UncomposedQp qp;
  UncomposedQpRows rows;
  EXPECT_TRUE(filter.BuildUncomposedQp(x.terms, x.qd, map, d.barriers, d.f_nominal, &qp, &rows));
  const Vector6d y = map.partialPivLu().solve(f);
  double worst = 1e300;
  for (int r = 0; r < rows.box; ++r) worst = std::min(worst, qp.a.row(r).dot(y) - qp.b(r));
  return worst;
}

TEST(PerBarrier, EveryAnswerMeetsEachBarrierAndTheClosedFormAnswersWhereItDoes) {
  const StackConfig& c = DefaultConfig();
  SafetyFilter checked(c.platform, CheckedConfig(true), c.actuators);
  SafetyFilter composed(c.platform, CheckedConfig(false), c.actuators);
  SafetyFilter uncomposed(c.platform, CheckedConfig(false, SafetyVariant::kUncomposed),
                          c.actuators);
  std::mt19937 rng(23);
  int replaced = 0, kept = 0, composed_broke = 0;
  for (int n = 0; n < 20000; ++n) {
    const FilterInput x = RandomFilterInput(&rng);
    SafetyDiagnostics dc, dk, du;
    const Vector6d f_composed = composed.StepWithTerms(x.terms, x.q, x.qd, x.f_des, &dc);
    const Vector6d f = checked.StepWithTerms(x.terms, x.q, x.qd, x.f_des, &dk);
    ASSERT_TRUE(f.allFinite());
    if (dc.flags & (kFlagFallback | kFlagInfeasible)) continue;
    const double composed_slack = WorstOwnConditionSlack(composed, x, dc, f_composed);
    if (dk.flags & kFlagPerBarrier) {
      ++replaced;
      // Only where the composed answer broke a barrier's own condition ...
      EXPECT_LT(composed_slack, 0.0) << "sample " << n;
      // ... and then the un-composed QP's answer, bit for bit.
      const Vector6d f_u = uncomposed.StepWithTerms(x.terms, x.q, x.qd, x.f_des, &du);
      EXPECT_TRUE(f == f_u) << "sample " << n;
      if (!(dk.flags & (kFlagFallback | kFlagInfeasible))) {
        EXPECT_GE(WorstOwnConditionSlack(checked, x, dk, f), -1e-9) << "sample " << n;
      }
    } else {
      ++kept;
      // The composed closed form's own answer, bit for bit, and it meets
      // every barrier's own condition.
      EXPECT_TRUE(f == f_composed) << "sample " << n;
      EXPECT_GE(composed_slack, -1e-7) << "sample " << n;
    }
    if (composed_slack < -1e-6) ++composed_broke;
  }
  // The check is not idle: on these states the composed answer breaks a
  // barrier's own condition often enough to matter, and every such answer
  // was replaced.
  EXPECT_GT(composed_broke, 100);
  EXPECT_GE(replaced, composed_broke);
  EXPECT_GT(kept, replaced);
  RecordProperty("replaced", replaced);
  RecordProperty("kept", kept);
}

// The paper's rule is the paper's: the check belongs to closed_form (and to
// the QP reference that stands in for its composed solve).
TEST(PerBarrier, ThePaperRuleIsNotChecked) {
  const StackConfig& c = DefaultConfig();
  SafetyFilter paper(c.platform, CheckedConfig(true, SafetyVariant::kPaperRule), c.actuators);
  std::mt19937 rng(29);
  for (int n = 0; n < 2000; ++n) {
    const FilterInput x = RandomFilterInput(&rng);
    SafetyDiagnostics d;
    paper.StepWithTerms(x.terms, x.q, x.qd, x.f_des, &d);
    EXPECT_FALSE(d.flags & kFlagPerBarrier) << "sample " << n;
  }
}

}  // namespace
}  // namespace stewart::safety::test
