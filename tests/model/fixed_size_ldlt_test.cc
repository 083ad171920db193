// FixedSizeLdlt against Eigen's LLT on random symmetric positive definite
// matrices, well and badly conditioned.
#include "stewart/model/fixed_size_ldlt.h"

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/QR>
#include <cmath>
#include <random>

namespace stewart {
namespace {

// Q diag(lambda) Q^T with eigenvalues spread over `log10_condition` decades.
template <int N>
Eigen::Matrix<double, N, N> RandomSpd(std::mt19937* rng, double log10_condition) {
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  Eigen::Matrix<double, N, N> a;
  for (int i = 0; i < N; ++i) {
    for (int j = 0; j < N; ++j) a(i, j) = normal(*rng);
  }
  const Eigen::Matrix<double, N, N> Q =
      Eigen::HouseholderQR<Eigen::Matrix<double, N, N>>(a).householderQ();
  Eigen::Matrix<double, N, 1> lambda;
  for (int i = 0; i < N; ++i) lambda(i) = std::pow(10.0, -log10_condition * unit(*rng));
  lambda(0) = 1.0;
  lambda(N - 1) = std::pow(10.0, -log10_condition);
  const Eigen::Matrix<double, N, N> m = Q * lambda.asDiagonal() * Q.transpose();
  return 0.5 * (m + m.transpose());
}

template <int N>
void CheckAgainstEigen(std::mt19937* rng, double log10_condition) {
  using Matrix = Eigen::Matrix<double, N, N>;
  using Vector = Eigen::Matrix<double, N, 1>;
  const double condition = std::pow(10.0, log10_condition);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (int n = 0; n < 500; ++n) {
    const Matrix a = RandomSpd<N>(rng, log10_condition);
    Vector b;
    for (int i = 0; i < N; ++i) b(i) = normal(*rng);
    const Eigen::LLT<Matrix> eigen(a);
    ASSERT_EQ(eigen.info(), Eigen::Success);
    // Only the lower triangle is read, as by Eigen::LLT.
    Matrix lower_only = a;
    lower_only.template triangularView<Eigen::StrictlyUpper>().setConstant(1e300);
    const FixedSizeLdlt<N> ours(lower_only);
    ASSERT_TRUE(ours.is_positive_definite());
    const Matrix L = ours.matrixL();
    const Vector D = ours.vectorD();
    EXPECT_LT((L * D.asDiagonal() * L.transpose() - a).cwiseAbs().maxCoeff(), 1e-15 * N);
    // The Cholesky factor of the same matrix is L sqrt(D).
    const Matrix L_eigen = eigen.matrixL();
    EXPECT_LT((L * D.cwiseSqrt().asDiagonal() - L_eigen).cwiseAbs().maxCoeff(),
              1e-15 * N * std::sqrt(condition));
    const Vector x = ours.Solve(b);
    const Vector x_eigen = eigen.solve(b);
    // Both are backward stable: the relative difference is ~ cond * eps.
    EXPECT_LT((x - x_eigen).norm(), 1e-15 * N * condition * x_eigen.norm());
    EXPECT_LT((a * x - b).norm(), 1e-15 * N * (a.norm() * x.norm() + b.norm()));
  }
}

TEST(FixedSizeLdlt, MatchesEigenLltWellConditioned) {
  std::mt19937 rng(40);
  CheckAgainstEigen<6>(&rng, 1.0);
  CheckAgainstEigen<3>(&rng, 1.0);
  CheckAgainstEigen<1>(&rng, 0.0);
}

// The platform's M spans ~4 decades (kg against kg m^2); beyond that too.
TEST(FixedSizeLdlt, MatchesEigenLltBadlyConditioned) {
  std::mt19937 rng(41);
  CheckAgainstEigen<6>(&rng, 4.0);
  CheckAgainstEigen<6>(&rng, 10.0);
}

TEST(FixedSizeLdlt, ReportsMatricesThatAreNotPositiveDefinite) {
  Matrix6d a = Matrix6d::Identity();
  a(3, 3) = -1.0;
  EXPECT_FALSE(Ldlt6d(a).is_positive_definite());
  a(3, 3) = 0.0;
  EXPECT_FALSE(Ldlt6d(a).is_positive_definite());
  a(3, 3) = std::nan("");
  EXPECT_FALSE(Ldlt6d(a).is_positive_definite());
  a(3, 3) = 1.0;
  a(4, 3) = 1.0;  // [[1, 1], [1, 1]] block: singular
  EXPECT_FALSE(Ldlt6d(a).is_positive_definite());
  a(4, 3) = 0.5;
  EXPECT_TRUE(Ldlt6d(a).is_positive_definite());
  EXPECT_FALSE(Ldlt6d().is_positive_definite());  // nothing factored yet
}

}  // namespace
}  // namespace stewart
