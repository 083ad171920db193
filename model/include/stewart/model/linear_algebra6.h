#pragma once
// Fixed-size 6x6 factorisations for the hot paths of every process: the
// mass matrix M (ForwardDynamics at every right-hand side of the simulator,
// the filter's barriers and metric, the estimator's prediction) and the
// force map H (InverseDynamics, the filter's F* when a constraint acts).
//
// Why not Eigen's LLT / PartialPivLU: at 6x6 both run their generic
// (runtime-sized, blocked) kernels, which cost a few times more than these
// (figures in docs/performance.md). The loops below have compile-time bounds
// and are unrolled; they are the textbook algorithms (square-root-free
// Cholesky L D L^T, one division and no square root per column; Gaussian
// elimination with partial pivoting), so the accuracy is Eigen's
// (tests/model/linear_algebra6_test.cc).
#include <cmath>
#include <utility>

#include "stewart/model/types.h"

namespace stewart {

/// Right-hand sides of Cholesky6::SolveInPlace: several are stored row-major
/// so that one SIMD operation updates a row of all of them.
template <int Cols>
using Rhs6 = Eigen::Matrix<double, 6, Cols, Cols == 1 ? Eigen::ColMajor : Eigen::RowMajor>;

/// Cholesky factorisation of a symmetric positive definite 6x6 matrix in its
/// square-root-free form A = L D L^T (L unit lower triangular, D > 0
/// diagonal), so the factor's critical path has one division and no square
/// root per column. Only the lower triangle of A is read.
class Cholesky6 {
 public:
  /// Factors `a`. Returns false, and leaves the factor unusable, unless
  /// every pivot d_j is positive and finite (A not positive definite, or
  /// NaN/Inf in it).
  bool Compute(const Matrix6d& a) {
    l_ = a;
#pragma GCC unroll 6
    for (int j = 0; j < 6; ++j) {
      const double d = l_(j, j);
      if (!(d > 0.0 && d < HUGE_VAL)) return false;  // also rejects NaN
      const double inv_d = 1.0 / d;
      d_(j) = d;
      inv_d_(j) = inv_d;
      // Column j still holds a_ij = l_ij d_j: update the trailing lower
      // triangle (right-looking), then scale the column to l_ij. Both work on
      // aligned row pairs (2m, 2m+1) of a column, one SIMD operation each;
      // where a pair starts one row above the triangle, the extra entry is in
      // the strictly upper part, which is scratch (never read as L).
#pragma GCC unroll 6
      for (int k = j + 1; k < 6; ++k) {
        const double l_kj = l_(k, j) * inv_d;
#pragma GCC unroll 3
        for (int m = k / 2; m < 3; ++m) {
          l_.col(k).template segment<2>(2 * m) -= l_kj * l_.col(j).template segment<2>(2 * m);
        }
      }
#pragma GCC unroll 3
      for (int m = (j + 1) / 2; m < 3; ++m) l_.col(j).template segment<2>(2 * m) *= inv_d;
    }
    return true;
  }

  /// B := A^-1 B, for one or more right-hand sides at once (one pass of the
  /// substitutions for all of them).
  template <int Cols>
  void SolveInPlace(Rhs6<Cols>* rhs) const {
    Rhs6<Cols>& b = *rhs;
#pragma GCC unroll 6
    for (int k = 0; k < 6; ++k) {  // L y = b
#pragma GCC unroll 6
      for (int i = k + 1; i < 6; ++i) b.row(i) -= l_(i, k) * b.row(k);
    }
#pragma GCC unroll 6
    for (int i = 0; i < 6; ++i) b.row(i) *= inv_d_(i);  // z = D^-1 y
#pragma GCC unroll 6
    for (int k = 5; k > 0; --k) {  // L^T x = z
#pragma GCC unroll 6
      for (int i = 0; i < k; ++i) b.row(i) -= l_(k, i) * b.row(k);
    }
  }

  /// A^-1 B.
  template <int Cols>
  Rhs6<Cols> Solve(Rhs6<Cols> b) const {
    SolveInPlace<Cols>(&b);
    return b;
  }

  /// L_M^-1 b for the factor L_M = L D^1/2 of MatrixL: the forward half of
  /// a solve, without forming L_M.
  Vector6d SolveFactorL(Vector6d b) const {
#pragma GCC unroll 6
    for (int k = 0; k < 6; ++k) {
#pragma GCC unroll 6
      for (int i = k + 1; i < 6; ++i) b(i) -= l_(i, k) * b(k);
    }
    for (int i = 0; i < 6; ++i) b(i) /= std::sqrt(d_(i));
    return b;
  }

  /// The Cholesky factor L_M of A = L_M L_M^T (L_M = L D^1/2, zero above the
  /// diagonal): what Eigen's LLT calls matrixL().
  Matrix6d MatrixL() const {
    Matrix6d l = l_.triangularView<Eigen::UnitLower>();
    for (int j = 0; j < 6; ++j) l.col(j) *= std::sqrt(d_(j));
    return l;
  }

 private:
  Matrix6d l_;  // strictly lower triangle: L; the rest is scratch
  Vector6d d_, inv_d_;
};

/// LU factorisation with partial pivoting of a 6x6 matrix, P A = L U (L unit
/// lower triangular), as Eigen's PartialPivLU, in fixed storage: one factor
/// for several solves.
class PartialPivLu6 {
 public:
  /// Factors `a`. Returns false, and leaves the factor unusable, when a
  /// pivot is zero or not finite (A singular or not finite).
  bool Compute(const Matrix6d& a) {
    lu_ = a;
#pragma GCC unroll 6
    for (int k = 0; k < 6; ++k) {
      int p = k;
      double best = std::fabs(lu_(k, k));
#pragma GCC unroll 6
      for (int i = k + 1; i < 6; ++i) {
        const double v = std::fabs(lu_(i, k));
        p = v > best ? i : p;
        best = v > best ? v : best;
      }
      if (!(best > 0.0 && best < HUGE_VAL)) return false;  // also rejects NaN
      swap_(k) = p;
      // Whole rows, the multipliers of earlier columns too, so that the
      // solve can apply P first.
      if (p != k) lu_.row(k).swap(lu_.row(p));
      inv_pivot_(k) = 1.0 / lu_(k, k);
#pragma GCC unroll 6
      for (int i = k + 1; i < 6; ++i) lu_(i, k) *= inv_pivot_(k);
#pragma GCC unroll 6
      for (int j = k + 1; j < 6; ++j) {
#pragma GCC unroll 6
        for (int i = k + 1; i < 6; ++i) lu_(i, j) -= lu_(i, k) * lu_(k, j);
      }
    }
    return true;
  }

  /// B := A^-1 B, for one or more right-hand sides at once.
  template <int Cols>
  void SolveInPlace(Eigen::Matrix<double, 6, Cols>* b) const {
    Eigen::Matrix<double, 6, Cols>& x = *b;
#pragma GCC unroll 6
    for (int k = 0; k < 6; ++k) {  // P, then L y = P b
      if (swap_(k) != k) x.row(k).swap(x.row(swap_(k)));
    }
#pragma GCC unroll 6
    for (int k = 0; k < 6; ++k) {
#pragma GCC unroll 6
      for (int c = 0; c < Cols; ++c) {
#pragma GCC unroll 6
        for (int i = k + 1; i < 6; ++i) x(i, c) -= lu_(i, k) * x(k, c);
      }
    }
#pragma GCC unroll 6
    for (int k = 5; k >= 0; --k) {  // U x = y
#pragma GCC unroll 6
      for (int c = 0; c < Cols; ++c) {
        x(k, c) *= inv_pivot_(k);
#pragma GCC unroll 6
        for (int i = 0; i < k; ++i) x(i, c) -= lu_(i, k) * x(k, c);
      }
    }
  }

 private:
  Matrix6d lu_;  // L strictly below the diagonal, U on and above it
  Vector6d inv_pivot_;
  Eigen::Matrix<int, 6, 1> swap_;  // row k was swapped with row swap_(k) >= k
};

/// Solves A X = B in place (B becomes X) by Gaussian elimination with partial
/// pivoting (PartialPivLu6). Returns false when a pivot is zero or not finite
/// (A singular or not finite); B is then unusable.
template <int Cols>
bool SolvePartialPivot6(const Matrix6d& a, Eigen::Matrix<double, 6, Cols>* b) {
  PartialPivLu6 lu;
  if (!lu.Compute(a)) return false;
  lu.SolveInPlace(b);
  return true;
}

}  // namespace stewart
