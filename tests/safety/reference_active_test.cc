// Variant qp's flag "active" (kFlagFilterActive) against the closed form's:
// the reference's rounding is not an intervention (kReferenceActiveRelTol,
// docs/safety.md "QP reference").
#include <gtest/gtest.h>

#include <cstdio>
#include <random>
#include <string>

#include "safety_test_support.h"
#include "stewart/safety/clp_reference_qp.h"

namespace stewart::safety::test {
namespace {

void CompareActiveFlags(CorrectionMetric metric) {
  SafetyConfig config = RichSafetyConfig();
  config.correction_metric = metric;
  SafetyFilter closed_form(DefaultConfig().platform, config, DefaultConfig().actuators);
  ClpReferenceQp clp;
  config.variant = SafetyVariant::kQpReference;
  SafetyFilter reference(DefaultConfig().platform, config, DefaultConfig().actuators, &clp);
  std::mt19937 rng(metric == CorrectionMetric::kForce ? 17 : 19);
  int inactive = 0, active = 0, near_zero = 0;
  const std::string name = ToString(metric);
  for (int n = 0; n < 4000; ++n) {
    const auto [q, qd, f_des, terms] = RandomFilterInput(&rng);
    SafetyDiagnostics dc, dr;
    closed_form.StepWithTerms(terms, q, qd, f_des, &dc);
    const Vector6d f_ref = reference.StepWithTerms(terms, q, qd, f_des, &dr);
    if (dc.infeasible || dr.infeasible) continue;
    const double scale = std::fmax(f_des.norm(), 1.0);
    const bool reference_active = dr.flags & kFlagFilterActive;
    if (dc.correction_norm == 0.0) {
      // No condition cuts F_des: the reference passes it unchanged.
      ++inactive;
      EXPECT_FALSE(reference_active) << name << " sample " << n;
      EXPECT_EQ(f_ref, f_des) << name << " sample " << n;
      EXPECT_EQ(dr.filter_case, FilterCase::kNone) << name << " sample " << n;
    } else if (dc.correction_norm > 2.0 * kReferenceActiveRelTol * scale) {
      ++active;
      EXPECT_TRUE(reference_active) << name << " sample " << n;
      EXPECT_EQ(dr.filter_case, dc.filter_case) << name << " sample " << n;
    } else {
      ++near_zero;  // within the tolerance of the closed form's own: either
    }
  }
  std::printf("%s: inactive %d, active %d, correction within 2x the tolerance %d\n", name.c_str(),
              inactive, active, near_zero);
  EXPECT_GT(inactive, 400);
  EXPECT_GT(active, 400);
  EXPECT_LT(near_zero, 10);
}

TEST(ReferenceActiveFlag, AgreesWithTheClosedFormForceMetric) {
  CompareActiveFlags(CorrectionMetric::kForce);
}
TEST(ReferenceActiveFlag, AgreesWithTheClosedFormAccelerationMetric) {
  CompareActiveFlags(CorrectionMetric::kAcceleration);
}

}  // namespace
}  // namespace stewart::safety::test
