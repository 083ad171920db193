// The two situations of NOTES.md where the paper's Theorem 1 is not the QP
// solution, constructed, solved by the exact case analysis, the paper rule
// and the Clp reference.
#include <gtest/gtest.h>

#include <cmath>

#include "stewart/safety/clp_reference_qp.h"
#include "stewart/safety/two_constraint_qp.h"

namespace stewart::safety {
namespace {

Vector6d Apply(const TwoConstraintProblem& p, const TwoConstraintSolution& s) {
  return s.mu_p * p.g_p + s.mu_v * p.g_v;  // F - F_des
}

Vector6d Reference(const TwoConstraintProblem& p) {
  ProjectionQp qp;
  qp.x0.setZero();  // F_des = 0: the solution is the correction itself
  qp.m = 2;
  qp.a.row(0) = p.g_p.transpose();
  qp.b(0) = -p.psi_p;
  qp.a.row(1) = p.g_v.transpose();
  qp.b(1) = -p.psi_v;
  ClpReferenceQp clp;
  Vector6d x;
  EXPECT_EQ(clp.Solve(qp, &x), ProjectionStatus::kOptimal);
  return x;
}

double PsiAfter(double psi, const Vector6d& g, const Vector6d& d) { return psi + g.dot(d); }

TEST(CaseAnalysis, BothViolatedButFixingOneFixesTheOther) {
  TwoConstraintProblem p;
  p.has_p = p.has_v = true;
  p.g_p << 1, 0, 0, 0, 0, 0;
  p.g_v << 1, 0.2, 0, 0, 0, 0;
  p.psi_p = -2.0;
  p.psi_v = -0.5;  // only-p correction mu_p = 2 gives psi_v = -0.5 + 2 > 0
  const TwoConstraintSolution exact = SolveExactKkt(p);
  EXPECT_EQ(exact.filter_case, FilterCase::kPosition);
  const Vector6d ref = Reference(p);
  EXPECT_LE((Apply(p, exact) - ref).norm(), 1e-9 * ref.norm());

  const TwoConstraintSolution paper = SolvePaperRule(p);
  EXPECT_EQ(paper.filter_case, FilterCase::kBoth);
  EXPECT_LT(paper.mu_v, 0.0);  // a negative multiplier: not a KKT point
  // Over-corrected: feasible but strictly farther from F_des than the QP.
  EXPECT_GT(Apply(p, paper).norm(), ref.norm() * (1 + 1e-3));
}

TEST(CaseAnalysis, OneViolatedButItsCorrectionViolatesTheOther) {
  TwoConstraintProblem p;
  p.has_p = p.has_v = true;
  p.g_p << 1, 0, 0, 0, 0, 0;
  p.g_v << -1, 1, 0, 0, 0, 0;
  p.g_v /= std::sqrt(2.0);
  p.psi_p = -1.0;
  p.psi_v = 0.1;  // after mu_p = 1: psi_v = 0.1 - 0.707 < 0
  const TwoConstraintSolution exact = SolveExactKkt(p);
  EXPECT_EQ(exact.filter_case, FilterCase::kBoth);
  EXPECT_GE(exact.mu_p, 0.0);
  EXPECT_GE(exact.mu_v, 0.0);
  const Vector6d ref = Reference(p);
  EXPECT_LE((Apply(p, exact) - ref).norm(), 1e-9 * ref.norm());

  const TwoConstraintSolution paper = SolvePaperRule(p);
  EXPECT_EQ(paper.filter_case, FilterCase::kPosition);
  // The paper's force breaks the velocity condition: unsafe.
  EXPECT_LT(PsiAfter(p.psi_v, p.g_v, Apply(p, paper)), -0.5);
  EXPECT_GE(PsiAfter(p.psi_v, p.g_v, Apply(p, exact)), -1e-12);
}

TEST(CaseAnalysis, VelocityOnlyAndNoneCases) {
  TwoConstraintProblem p;
  p.has_p = p.has_v = true;
  p.g_p << 0, 1, 0, 0, 0, 0;
  p.g_v << 0, 0, 2, 0, 0, 0;
  p.psi_p = 0.3;
  p.psi_v = -1.0;
  const TwoConstraintSolution s = SolveExactKkt(p);
  EXPECT_EQ(s.filter_case, FilterCase::kVelocity);
  EXPECT_DOUBLE_EQ(s.mu_v, 0.25);
  p.psi_v = 0.0;
  EXPECT_EQ(SolveExactKkt(p).filter_case, FilterCase::kNone);
}

TEST(CaseAnalysis, AbsentGroupIsNeverActive) {
  TwoConstraintProblem p;
  p.has_p = true;
  p.has_v = false;
  p.g_p << 1, 0, 0, 0, 0, 0;
  p.psi_p = -1.0;
  p.psi_v = -5.0;  // garbage in an absent group must be ignored
  const TwoConstraintSolution s = SolveExactKkt(p);
  EXPECT_EQ(s.filter_case, FilterCase::kPosition);
  EXPECT_DOUBLE_EQ(s.mu_p, 1.0);
  EXPECT_EQ(s.mu_v, 0.0);
}

}  // namespace
}  // namespace stewart::safety
