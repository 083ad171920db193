// Closed form == QP reference on 1e5 random states and nominal forces
// (ctest label `long`). The reference solves exactly the QP the filter
// poses (SafetyFilter::BuildQp), so this checks the case analysis.
#include <gtest/gtest.h>

#include <array>
#include <memory>

#include "safety_test_support.h"
#include "stewart/safety/clp_reference_qp.h"
#ifdef STEWART_HAVE_ALGLIB
#include "stewart/safety/alglib_reference_qp.h"
#endif

namespace stewart::safety::test {
namespace {

constexpr int kSamples = 100000;
constexpr double kRelTol = 1e-9;
// Clp's answer is the exact projection on the active set its interior point
// finds, certified by KKT (ClpReferenceQp), so it meets the same 1e-9.
constexpr double kClpRelTol = 1e-9;

void Sweep(ReferenceQpSolver* reference, bool force_limits, CorrectionMetric metric, int samples,
           double rel_tol = kRelTol) {
  SafetyConfig config = RichSafetyConfig();
  config.force_limits_enabled = force_limits;
  config.correction_metric = metric;
  SafetyFilter filter(DefaultConfig().platform, config, DefaultConfig().actuators);
  SafetyFilter paper(DefaultConfig().platform, config, DefaultConfig().actuators);
  paper.set_variant(SafetyVariant::kPaperRule);
  std::mt19937 rng(force_limits ? 11 : 7);
  std::array<int, 6> cases{};
  int paper_differs = 0, both_infeasible = 0;
  double worst = 0.0;
  for (int n = 0; n < samples; ++n) {
    const auto [q, qd, f_des, terms] = RandomFilterInput(&rng);
    SafetyDiagnostics d;
    const Vector6d f = filter.StepWithTerms(terms, q, qd, f_des, &d);
    ++cases[static_cast<size_t>(d.filter_case)];
    ProjectionQp qp;
    Vector6d y_ref = f_des;
    const Matrix6d t = filter.MetricMap(terms);
    const bool posable = filter.BuildQp(t, d.barriers, f_des, &qp);
    const ProjectionStatus status =
        posable ? reference->Solve(qp, &y_ref) : ProjectionStatus::kInfeasible;
    const Vector6d f_ref = SafetyFilter::ForceFromQpSolution(t, y_ref);
    if (d.infeasible) {
      // Both must agree that there is no solution.
      EXPECT_NE(status, ProjectionStatus::kOptimal) << "sample " << n;
      ++both_infeasible;
      continue;
    }
    ASSERT_EQ(status, ProjectionStatus::kOptimal) << "sample " << n;
    const double err = RelativeError(f, f_ref);
    worst = std::max(worst, err);
    ASSERT_LE(err, rel_tol) << "sample " << n << " case " << static_cast<int>(d.filter_case)
                            << "\nF*  " << f.transpose() << "\nref " << f_ref.transpose();
    if (!force_limits) {
      SafetyDiagnostics dp;
      const Vector6d f_paper = paper.StepWithTerms(terms, q, qd, f_des, &dp);
      if (RelativeError(f_paper, f_ref) > 1e-6) ++paper_differs;
    }
  }
  ::testing::Test::RecordProperty("worst_relative_error", std::to_string(worst));
  std::printf(
      "%s%s%s: worst rel err %.3g; cases none %d pos %d vel %d both %d infeasible %d; "
      "paper rule differs from QP in %d\n",
      reference->name(), force_limits ? " (force limits)" : "",
      metric == CorrectionMetric::kForce          ? " (force metric)"
      : metric == CorrectionMetric::kAcceleration ? " (acceleration metric)"
                                                  : " (task acceleration metric)",
      worst, cases[0], cases[1], cases[2], cases[3], cases[4], paper_differs);
  // The sweep must exercise every feasible case, or it proves little.
  EXPECT_GT(cases[0], samples / 100);
  EXPECT_GT(cases[1], samples / 100);
  EXPECT_GT(cases[2], samples / 100);
  EXPECT_GT(cases[3], samples / 1000);
  if (!force_limits) {
    EXPECT_GT(paper_differs, 0);
  }
  (void)both_infeasible;
}

constexpr CorrectionMetric kForceMetric = CorrectionMetric::kForce;
constexpr CorrectionMetric kAccelMetric = CorrectionMetric::kAcceleration;
constexpr CorrectionMetric kTaskMetric = CorrectionMetric::kTaskAcceleration;

TEST(ReferenceSweep, ClosedFormEqualsClp) {
  ClpReferenceQp clp;
  Sweep(&clp, false, kForceMetric, kSamples, kClpRelTol);
  Sweep(&clp, false, kAccelMetric, kSamples, kClpRelTol);
}

TEST(ReferenceSweep, ForceLimitedEqualsClp) {
  ClpReferenceQp clp;
  Sweep(&clp, true, kForceMetric, kSamples / 4, kClpRelTol);
  Sweep(&clp, true, kAccelMetric, kSamples / 4, kClpRelTol);
}

TEST(ReferenceSweep, TaskAccelerationMetricEqualsClp) {
  ClpReferenceQp clp;
  Sweep(&clp, false, kTaskMetric, kSamples, kClpRelTol);
  Sweep(&clp, true, kTaskMetric, kSamples / 4, kClpRelTol);
}

#ifdef STEWART_HAVE_ALGLIB
TEST(ReferenceSweep, ClosedFormEqualsAlglib) {
  AlglibReferenceQp alglib;
  Sweep(&alglib, false, kForceMetric, kSamples);
}

TEST(ReferenceSweep, ClosedFormEqualsAlglibAccelerationMetric) {
  AlglibReferenceQp alglib;
  Sweep(&alglib, false, kAccelMetric, kSamples);
}

TEST(ReferenceSweep, ForceLimitedEqualsAlglib) {
  AlglibReferenceQp alglib;
  Sweep(&alglib, true, kForceMetric, kSamples / 4);
  Sweep(&alglib, true, kAccelMetric, kSamples / 4);
}

TEST(ReferenceSweep, TaskAccelerationMetricEqualsAlglib) {
  AlglibReferenceQp alglib;
  Sweep(&alglib, false, kTaskMetric, kSamples);
  Sweep(&alglib, true, kTaskMetric, kSamples / 4);
}
#endif

}  // namespace
}  // namespace stewart::safety::test
