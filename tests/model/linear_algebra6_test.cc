// The fixed-size 6x6 factorisations (linear_algebra6.h) against Eigen's LLT
// and PartialPivLU, on the model's M and H and on random matrices of wide
// conditioning, plus the failure reports.
#include "stewart/model/linear_algebra6.h"

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <cmath>
#include <limits>

#include "stewart/model/dynamics.h"
#include "test_states.h"

namespace stewart::test {
namespace {

// Random matrix with singular values spread over `decades` decades.
Matrix6d RandomMatrix(std::mt19937* rng, double decades) {
  std::normal_distribution<double> n;
  Matrix6d a, b;
  for (int i = 0; i < 36; ++i) {
    a(i) = n(*rng);
    b(i) = n(*rng);
  }
  const Eigen::HouseholderQR<Matrix6d> qa(a), qb(b);
  Vector6d s;
  for (int i = 0; i < 6; ++i) s(i) = std::pow(10.0, -decades * i / 5.0);
  return Matrix6d(qa.householderQ()) * s.asDiagonal() * Matrix6d(qb.householderQ()).transpose();
}

Vector6d RandomVector(std::mt19937* rng) {
  std::normal_distribution<double> n;
  Vector6d v;
  for (int i = 0; i < 6; ++i) v(i) = n(*rng);
  return v;
}

// The 2-norm condition number: largest over smallest singular value.
double ConditionNumber(const Matrix6d& a) {
  const Eigen::JacobiSVD<Matrix6d> svd(a);
  return svd.singularValues()(0) / svd.singularValues()(5);
}

// Backward-stable solvers agree to ~cond * eps.
void ExpectCholeskyMatchesEigen(const Matrix6d& a, const Vector6d& b, double cond) {
  Cholesky6 chol;
  // Only the lower triangle is read, as by Eigen::LLT.
  Matrix6d lower_only = a;
  lower_only.triangularView<Eigen::StrictlyUpper>().setConstant(1e300);
  ASSERT_TRUE(chol.Compute(lower_only));
  const Eigen::LLT<Matrix6d> llt(a);
  ASSERT_EQ(llt.info(), Eigen::Success);
  const Matrix6d l_ref = llt.matrixL();
  EXPECT_LE((chol.MatrixL() - l_ref).norm(), 1e-13 * std::sqrt(cond) * l_ref.norm());
  EXPECT_EQ(chol.MatrixL().triangularView<Eigen::StrictlyUpper>().toDenseMatrix(),
            Matrix6d::Zero());
  const Vector6d x_ref = llt.solve(b);
  EXPECT_LE((chol.Solve<1>(b) - x_ref).norm(), 1e-13 * cond * x_ref.norm());
  // The forward half alone: L_M^-1 b. The two factors differ by up to
  // 1e-13 sqrt(cond) relative (above) and the solve amplifies that by
  // cond(L_M) = sqrt(cond).
  const Vector6d half_ref = llt.matrixL().solve(b);
  EXPECT_LE((chol.SolveFactorL(b) - half_ref).norm(), 1e-13 * cond * half_ref.norm());
  // Several right-hand sides at once give the same as one at a time.
  Eigen::Matrix<double, 6, 2> two;
  two << b, 2.0 * b.reverse();
  const Eigen::Matrix<double, 6, 2> x2 = chol.Solve<2>(two);
  EXPECT_EQ(x2.col(0), chol.Solve<1>(b));
  EXPECT_EQ(x2.col(1), chol.Solve<1>(two.col(1)));
}

void ExpectLuMatchesEigen(const Matrix6d& a, const Vector6d& b, double cond) {
  const Eigen::PartialPivLU<Matrix6d> lu(a);
  Vector6d x = b;
  ASSERT_TRUE(SolvePartialPivot6(a, &x));
  const Vector6d x_ref = lu.solve(b);
  EXPECT_LE((x - x_ref).norm(), 1e-13 * cond * x_ref.norm());
  Matrix6d xs = Matrix6d::Identity();
  ASSERT_TRUE(SolvePartialPivot6(a, &xs));
  const Matrix6d xs_ref = lu.inverse();
  EXPECT_LE((xs - xs_ref).norm(), 1e-13 * cond * xs_ref.norm());
}

TEST(LinearAlgebra6, CholeskyOfTheModelsInertiaMatchesEigen) {
  ForRandomPoses(41, 500, [&](const Vector6d& q, std::mt19937* rng) {
    const DynamicsTerms t = EvaluateDynamics(DefaultConfig().platform, q, RandomVelocity(rng));
    ExpectCholeskyMatchesEigen(t.M, RandomVector(rng), ConditionNumber(t.M));
  });
}

TEST(LinearAlgebra6, CholeskyOfRandomMatricesMatchesEigen) {
  std::mt19937 rng(43);
  for (int n = 0; n < 2000; ++n) {
    const double decades = 8.0 * (n % 9) / 8.0;  // cond(A) up to 1e8
    const Matrix6d r = RandomMatrix(&rng, decades / 2.0);
    const Matrix6d a = r.transpose() * r * std::pow(10.0, (n % 7) - 3.0);  // any scale
    ExpectCholeskyMatchesEigen(a, RandomVector(&rng), std::pow(10.0, decades));
  }
}

TEST(LinearAlgebra6, CholeskyReportsWhatIsNotPositiveDefinite) {
  Cholesky6 chol;
  Matrix6d a = Matrix6d::Identity();
  a(3, 3) = 0.0;
  EXPECT_FALSE(chol.Compute(a));  // semi-definite
  a(3, 3) = -1.0;
  EXPECT_FALSE(chol.Compute(a));  // indefinite
  a = Matrix6d::Identity();
  a(5, 0) = 2.0;  // |a_50| > 1: indefinite, found at the last pivot
  EXPECT_FALSE(chol.Compute(a));
  a = Matrix6d::Identity();
  a(2, 1) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(chol.Compute(a));
  a = Matrix6d::Identity();
  a(4, 4) = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(chol.Compute(a));
  EXPECT_TRUE(chol.Compute(Matrix6d::Identity() * 1e-300));  // tiny but definite
}

TEST(LinearAlgebra6, PartialPivotSolveOfTheModelsHMatchesEigen) {
  ForRandomPoses(47, 500, [&](const Vector6d& q, std::mt19937* rng) {
    const DynamicsTerms t = EvaluateDynamics(DefaultConfig().platform, q, Vector6d::Zero());
    ExpectLuMatchesEigen(t.H, RandomVector(rng), ConditionNumber(t.H));
  });
}

TEST(LinearAlgebra6, PartialPivotSolveOfRandomMatricesMatchesEigen) {
  std::mt19937 rng(53);
  for (int n = 0; n < 2000; ++n) {
    const double decades = 8.0 * (n % 9) / 8.0;
    const Matrix6d a = RandomMatrix(&rng, decades) * std::pow(10.0, (n % 7) - 3.0);
    ExpectLuMatchesEigen(a, RandomVector(&rng), std::pow(10.0, decades));
  }
}

TEST(LinearAlgebra6, PartialPivotSolveReportsSingularAndNonFiniteMatrices) {
  Matrix6d a = Matrix6d::Identity();
  a.row(4) = a.row(1);  // rank 5: a zero pivot appears
  Vector6d x = Vector6d::Ones();
  EXPECT_FALSE(SolvePartialPivot6(a, &x));
  EXPECT_FALSE(SolvePartialPivot6(Matrix6d::Zero().eval(), &x));
  a = Matrix6d::Identity();
  a(0, 3) = std::numeric_limits<double>::quiet_NaN();
  x.setOnes();
  const bool ok = SolvePartialPivot6(a, &x);
  EXPECT_TRUE(!ok || !x.allFinite());  // NaN off the pivot column reaches x, never hidden
  a = Matrix6d::Identity();
  a(2, 2) = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(SolvePartialPivot6(a, &x));
}

}  // namespace
}  // namespace stewart::test
