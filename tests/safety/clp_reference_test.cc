// ClpReferenceQp on QPs that broke earlier ways of posing them to Clp, and on
// the edge cases its certificate must get right. The states come from a 40 s
// paper run with the P-16P legs in the task-acceleration metric, force limits
// on (two barrier rows, twelve leg-force rows, in the metric's coordinates).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "stewart/safety/clp_reference_qp.h"
#include "stewart/safety/projection_qp.h"

namespace stewart::safety::test {
namespace {

// Clp's QP simplex (primal(), free columns, tolerances 1e-12) cycled on this
// one without end: both barrier rows active.
ProjectionQp CycledState() {
  ProjectionQp qp;
  qp.m = 14;
  qp.a.row(0) << -0.0032112041446524442, 0.99793926851948223, -0.061963006415921201,
      0.0031284009741825314, -0.01041425605408107, -0.012216657841959454;
  qp.b(0) = -0.64407636869719986;
  qp.a.row(1) << -0.72376544810360866, -0.091483003042832772, -0.68395499580429098, 0,
      -1.4052269145768866e-17, 2.0074670208241239e-18;
  qp.b(1) = -0.26719508254201907;
  qp.a.row(2) << -19.349972098435746, -0.35454493635401785, 78.071491277062691, -9.5429726143444462,
      -8.0181370455906418, -2.3110124037990496;
  qp.b(2) = -100;
  qp.a.row(3) << 19.349972098435746, 0.35454493635401785, -78.071491277062691, 9.5429726143444462,
      8.0181370455906418, 2.3110124037990496;
  qp.b(3) = -100;
  qp.a.row(4) << -17.848593274026307, 32.434730701995818, 71.406160068118197, 8.7600369722582663,
      -7.3474472360480494, 5.4181315958439127;
  qp.b(4) = -100;
  qp.a.row(5) << 17.848593274026307, -32.434730701995818, -71.406160068118197, -8.7600369722582663,
      7.3474472360480494, -5.4181315958439127;
  qp.b(5) = -100;
  qp.a.row(6) << 24.236580178601969, 9.5094238686077155, 76.10133938891687, 11.427661245781595,
      -4.1621487648670525, -3.0218126754428414;
  qp.b(6) = -100;
  qp.a.row(7) << -24.236580178601969, -9.5094238686077155, -76.10133938891687, -11.427661245781595,
      4.1621487648670525, 3.0218126754428414;
  qp.b(7) = -100;
  qp.a.row(8) << -6.1453526962030862, -8.1355236965682369, 79.783618950271688, 2.2129113317458455,
      12.536755063152903, 1.3571370022412306;
  qp.b(8) = -100;
  qp.a.row(9) << 6.1453526962030862, 8.1355236965682369, -79.783618950271688, -2.2129113317458455,
      -12.536755063152903, -1.3571370022412306;
  qp.b(9) = -100;
  qp.a.row(10) << -5.4778672401711832, 38.928450724374009, 70.173624943898702, -1.9581066447650168,
      11.075416538376929, -6.1776155966527577;
  qp.b(10) = -100;
  qp.a.row(11) << 5.4778672401711832, -38.928450724374009, -70.173624943898702, 1.9581066447650168,
      -11.075416538376929, 6.1776155966527577;
  qp.b(11) = -100;
  qp.a.row(12) << 23.390647219701449, 23.656966353379445, 73.232888137953537, -11.018391200550731,
      -3.9989796212719138, 4.7055322956318522;
  qp.b(12) = -100;
  qp.a.row(13) << -23.390647219701449, -23.656966353379445, -73.232888137953537, 11.018391200550731,
      3.9989796212719138, -4.7055322956318522;
  qp.b(13) = -100;
  qp.x0 << 0.034791461937313799, -2.6474160390535806, 1.3755385154316477, 0.064117867407639792,
      -0.015813570718673901, 0.21422999672276696;
  return qp;
}

// With the columns boxed at +-1e6, Clp's QP simplex called this one
// (feasible: one barrier row active) primal infeasible.
ProjectionQp BoxedInfeasibleState() {
  ProjectionQp qp;
  qp.m = 14;
  qp.a.row(0) << 0.11234117076160098, -0.92812921747812493, -0.3522155004904034,
      -0.043418189314148557, -0.0018294562972895291, 0.0033722627400875576;
  qp.b(0) = -0.79719227165558848;
  qp.a.row(1) << -0.04107913449928767, -0.99905684298251818, -0.014068731236107667,
      6.5395835190792553e-17, 0, 1.4532407820176122e-17;
  qp.b(1) = -0.84680340840185797;
  qp.a.row(2) << -19.227553464727109, -5.1362254285326943, 77.933765953173008, -9.5337348234895138,
      -8.01028439888176, -2.7918190572284338;
  qp.b(2) = -100;
  qp.a.row(3) << 19.227553464727109, 5.1362254285326943, -77.933765953173008, 9.5337348234895138,
      8.01028439888176, 2.7918190572284338;
  qp.b(3) = -100;
  qp.a.row(4) << -17.962314291960364, 28.406786798696039, 73.073428048950134, 8.964297726307505,
      -7.5185875210937976, 5.0253309637428663;
  qp.b(4) = -100;
  qp.a.row(5) << 17.962314291960364, -28.406786798696039, -73.073428048950134, -8.964297726307505,
      7.5185875210937976, -5.0253309637428663;
  qp.b(5) = -100;
  qp.a.row(6) << 24.347453223239942, 4.8312931280968252, 76.506992904146429, 11.485633657157345,
      -4.1832160436868699, -3.2865587951914321;
  qp.b(6) = -100;
  qp.a.row(7) << -24.347453223239942, -4.8312931280968252, -76.506992904146429, -11.485633657157345,
      4.1832160436868699, 3.2865587951914321;
  qp.b(7) = -100;
  qp.a.row(8) << -5.9993834053209145, -12.704022666640203, 79.195390918688233, 2.1981464718795061,
      12.452394433643569, 2.0737458075474815;
  qp.b(8) = -100;
  qp.a.row(9) << 5.9993834053209145, 12.704022666640203, -79.195390918688233, -2.1981464718795061,
      -12.452394433643569, -2.0737458075474815;
  qp.b(9) = -100;
  qp.a.row(10) << -5.5500832683026893, 35.366176820355548, 72.029533224558577, -2.0085065962561743,
      11.361155140995788, -5.6205978449411669;
  qp.b(10) = -100;
  qp.a.row(11) << 5.5500832683026893, -35.366176820355548, -72.029533224558577, 2.0085065962561743,
      -11.361155140995788, 5.6205978449411669;
  qp.b(11) = -100;
  qp.a.row(12) << 23.508277832166598, 19.31731660700099, 74.456895381787206, -11.194507355251909,
      -4.0630282394116657, 4.4807693924964322;
  qp.b(12) = -100;
  qp.a.row(13) << -23.508277832166598, -19.31731660700099, -74.456895381787206, 11.194507355251909,
      4.0630282394116657, -4.4807693924964322;
  qp.b(13) = -100;
  qp.x0 << -0.096150695796353117, 1.6433881368554291, -0.070111332792987577, 0.10948754793723176,
      0.05197755283784946, -0.012869986503316574;
  return qp;
}

void ExpectSameAnswerAsTheActiveSetSolver(const ProjectionQp& qp) {
  ClpReferenceQp clp;
  Vector6d x = Vector6d::Constant(std::nan(""));
  ASSERT_EQ(clp.Solve(qp, &x), ProjectionStatus::kOptimal);
  const ProjectionResult expected = SolveProjectionQp(qp);
  ASSERT_EQ(expected.status, ProjectionStatus::kOptimal);
  EXPECT_LT((x - expected.x).norm(), 1e-12 * std::max(1.0, expected.x.norm()))
      << "clp " << x.transpose() << "\nexpected " << expected.x.transpose();
  for (int r = 0; r < qp.m; ++r) {
    EXPECT_GE(qp.a.row(r).dot(x) - qp.b(r), -1e-12 * qp.a.row(r).norm()) << "row " << r;
  }
}

TEST(ClpReference, AnswersTheStateItsSimplexCycledOn) {
  const ProjectionQp qp = CycledState();
  ExpectSameAnswerAsTheActiveSetSolver(qp);
  // Both barrier rows active, no force row.
  ClpReferenceQp clp;
  Vector6d x;
  ASSERT_EQ(clp.Solve(qp, &x), ProjectionStatus::kOptimal);
  EXPECT_NEAR(qp.a.row(0).dot(x), qp.b(0), 1e-12);
  EXPECT_NEAR(qp.a.row(1).dot(x), qp.b(1), 1e-12);
}

TEST(ClpReference, AnswersTheStateBoxedColumnsCalledInfeasible) {
  ExpectSameAnswerAsTheActiveSetSolver(BoxedInfeasibleState());
}

TEST(ClpReference, ReturnsTheStartWhenItIsFeasible) {
  ProjectionQp qp = CycledState();
  qp.x0 = Vector6d::Zero();
  for (int r = 0; r < qp.m; ++r) qp.b(r) = -1.0;
  ClpReferenceQp clp;
  Vector6d x;
  ASSERT_EQ(clp.Solve(qp, &x), ProjectionStatus::kOptimal);
  EXPECT_EQ(x, Vector6d::Zero());
}

TEST(ClpReference, MergesRowsWithTheSameNormal) {
  // x_0 >= 1 three times over (scaled copies), x_0 + x_1 >= 3: the answer
  // (1.5, 1.5) has three dependent rows and one other active.
  ProjectionQp qp;
  qp.m = 4;
  qp.a.setZero();
  qp.a(0, 0) = 1.0;
  qp.b(0) = 1.0;
  qp.a(1, 0) = 2.0;
  qp.b(1) = 2.0;
  qp.a(2, 0) = 0.5;
  qp.b(2) = 0.5;
  qp.a(3, 0) = 1.0;
  qp.a(3, 1) = 1.0;
  qp.b(3) = 3.0;
  ClpReferenceQp clp;
  Vector6d x;
  ASSERT_EQ(clp.Solve(qp, &x), ProjectionStatus::kOptimal);
  Vector6d expected = Vector6d::Zero();
  expected(0) = 1.5;
  expected(1) = 1.5;
  EXPECT_LT((x - expected).norm(), 1e-12) << x.transpose();
}

TEST(ClpReference, ReportsAnEmptySetInfeasible) {
  // x_2 >= 1 and -x_2 >= 0.
  ProjectionQp qp;
  qp.m = 2;
  qp.a.setZero();
  qp.a(0, 2) = 1.0;
  qp.b(0) = 1.0;
  qp.a(1, 2) = -1.0;
  qp.b(1) = 0.0;
  ClpReferenceQp clp;
  Vector6d x;
  EXPECT_EQ(clp.Solve(qp, &x), ProjectionStatus::kInfeasible);
}

TEST(ClpReference, RejectsAZeroRow) {
  ProjectionQp qp;
  qp.m = 1;
  qp.a.setZero();
  qp.b(0) = 1.0;
  ClpReferenceQp clp;
  Vector6d x;
  EXPECT_NE(clp.Solve(qp, &x), ProjectionStatus::kOptimal);
}

}  // namespace
}  // namespace stewart::safety::test
