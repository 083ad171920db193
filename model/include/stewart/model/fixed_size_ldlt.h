#pragma once
// Square-root-free Cholesky factorisation A = L D L^T (L unit lower
// triangular, D diagonal) of a small fixed-size symmetric positive definite
// matrix, for the model's hot paths: ForwardDynamics factors the 6x6 M at
// every right-hand side of the simulator and in the filter and estimator.
//
// Why not Eigen::LLT: it is generic over sizes (run-time loop bounds, blocked
// code). Here every loop bound is a compile-time constant and the loops are
// unrolled completely, and L D L^T needs one division per column and no
// square root: the factorisation is one dependency chain through the
// columns, and a square root followed by a division was most of each link.
// The reciprocals of D are kept, so a solve has no division at all.
// Measured against Eigen::LLT in docs/performance.md ("Model").
//
// No pivoting: for a symmetric positive definite A the factorisation is
// backward stable without it (as Cholesky is). Like Eigen::LLT only the
// lower triangle of A is read, and a matrix that is not numerically positive
// definite is not rejected (its solves then hold garbage, NaN or inf):
// is_positive_definite() tells.
#include "stewart/model/types.h"

namespace stewart {

template <int N>
class FixedSizeLdlt {
 public:
  using Matrix = Eigen::Matrix<double, N, N>;
  using Vector = Eigen::Matrix<double, N, 1>;

  FixedSizeLdlt() = default;
  explicit FixedSizeLdlt(const Matrix& a) { Compute(a); }

  /// Factors A (its lower triangle). No heap allocation.
  void Compute(const Matrix& a) {
    positive_definite_ = true;
    // Column j: d_j = a_jj - sum_k L_jk^2 d_k, then for i > j
    // t_ij = a_ij - sum_k L_ik L_jk d_k = L_ij d_j. The strict upper triangle
    // of lu_ keeps t (lu_(j, i) = L_ij d_j), the strict lower one L, the
    // diagonal D.
#pragma GCC unroll 8
    for (int j = 0; j < N; ++j) {
      double d = a(j, j);
#pragma GCC unroll 8
      for (int k = 0; k < j; ++k) d -= lu_(j, k) * lu_(k, j);
      positive_definite_ = positive_definite_ && d > 0.0;
      const double inv_d = 1.0 / d;
      lu_(j, j) = d;
      inv_d_(j) = inv_d;
#pragma GCC unroll 8
      for (int i = j + 1; i < N; ++i) {
        double t = a(i, j);
#pragma GCC unroll 8
        for (int k = 0; k < j; ++k) t -= lu_(i, k) * lu_(k, j);
        lu_(j, i) = t;
        lu_(i, j) = t * inv_d;
      }
    }
  }

  /// x = A^-1 b: L y = b forward, then L^T x = D^-1 y backward.
  Vector Solve(const Vector& b) const {
    Vector y;
#pragma GCC unroll 8
    for (int i = 0; i < N; ++i) {
      double sum = b(i);
#pragma GCC unroll 8
      for (int k = 0; k < i; ++k) sum -= lu_(i, k) * y(k);
      y(i) = sum;
    }
    Vector x;
#pragma GCC unroll 8
    for (int i = N - 1; i >= 0; --i) {
      double sum = y(i) * inv_d_(i);
#pragma GCC unroll 8
      for (int k = i + 1; k < N; ++k) sum -= lu_(k, i) * x(k);
      x(i) = sum;
    }
    return x;
  }

  /// The unit lower triangular L.
  Matrix matrixL() const {
    Matrix l = lu_.template triangularView<Eigen::StrictlyLower>();
    l.diagonal().setOnes();
    return l;
  }
  /// The diagonal of D.
  Vector vectorD() const { return lu_.diagonal(); }

  /// False iff a pivot d_j was not positive (or NaN): A is not (numerically)
  /// positive definite and the solves are meaningless.
  bool is_positive_definite() const { return positive_definite_; }

 private:
  Matrix lu_ = Matrix::Zero();  // strictly lower: L; diagonal: D; strictly upper: (L D)^T
  Vector inv_d_ = Vector::Zero();
  bool positive_definite_ = false;
};

using Ldlt6d = FixedSizeLdlt<6>;

}  // namespace stewart
