#pragma once
// Exact solver of the small projection QPs behind the force-limited filter
// and the un-composed variant:
//
//   min 1/2 ||x - x0||^2   s.t.  a_i^T x >= b_i,  i < m  (x in R^6, m <= MaxRows)
//
// Goldfarb-Idnani dual active-set method with identity Hessian: start at the
// unconstrained minimum x0, add the most violated constraint, and move along
// the part of a_p orthogonal to the active normals while keeping every
// multiplier non-negative (dropping a constraint whose multiplier reaches 0).
// It terminates after finitely many active-set changes at the exact KKT
// point, or proves infeasibility (a_p depends on active normals with
// non-positive weights). At most 6 rows are active at once (their normals
// stay linearly independent in R^6), whatever the row capacity.
//
// The row capacity is a compile-time parameter so that each QP keeps
// fixed-size storage (no heap allocation) sized for what it poses: the
// composed filter's 2 + 12 rows (ProjectionQp, the default), the
// un-composed variant's up to 24 + 12 + 12 (uncomposed_qp.h). Instantiated
// for those two capacities in projection_qp.cc.
#include <array>

#include "stewart/common/check.h"
#include "stewart/model/types.h"

namespace stewart::safety {

/// Rows of the composed filter's QP: 2 CBF conditions + 2 force limits per leg.
constexpr int kMaxQpRows = 2 + 2 * kNumLegs;

template <int MaxRows>
struct ProjectionQpN {
  static constexpr int kMaxRows = MaxRows;
  int m = 0;
  Eigen::Matrix<double, MaxRows, 6> a;  ///< rows a_i^T
  Eigen::Matrix<double, MaxRows, 1> b;
  Vector6d x0 = Vector6d::Zero();
};

enum class ProjectionStatus { kOptimal, kInfeasible, kIterationLimit };

template <int MaxRows>
struct ProjectionResultN {
  ProjectionStatus status = ProjectionStatus::kOptimal;
  Vector6d x = Vector6d::Zero();
  Eigen::Matrix<double, MaxRows, 1> mu;  ///< x = x0 + sum mu_i a_i, mu >= 0
  int iterations = 0;
};

using ProjectionQp = ProjectionQpN<kMaxQpRows>;
using ProjectionResult = ProjectionResultN<kMaxQpRows>;

template <int MaxRows>
ProjectionResultN<MaxRows> SolveProjectionQp(const ProjectionQpN<MaxRows>& qp);

extern template ProjectionResultN<kMaxQpRows> SolveProjectionQp(const ProjectionQpN<kMaxQpRows>&);

/// A normal shorter than this (W/N = m/s for g_p) counts as zero: the
/// condition cannot be changed by the force (e.g. g_p = -H^T qd at rest).
constexpr double kZeroNormal = 1e-12;

/// Where AppendConditionRow put a condition.
struct ConditionRow {
  int row = -1;         ///< -1: not posed (zero normal)
  double norm = 0.0;    ///< |n| of a posed row: its multiplier is the row's / |n|
  bool posable = true;  ///< false: a zero normal and a violated condition
};

/// Appends psi + n^T (x - x0) >= 0 (x0 = qp->x0) as the unit-normal row
/// (n/|n|)^T x >= (n^T x0 - psi)/|n|, so that the solver's row multipliers
/// compare across conditions of different units. A zero normal poses no row:
/// the force cannot change the condition, which then either holds or makes
/// the QP unposable (no force can satisfy it).
template <int MaxRows>
ConditionRow AppendConditionRow(double psi, const Vector6d& normal, ProjectionQpN<MaxRows>* qp) {
  ConditionRow r;
  const double norm = normal.norm();
  if (!(norm > kZeroNormal)) {
    r.posable = !(psi < 0.0);
    return r;
  }
  STEWART_CHECK(qp->m < MaxRows, "AppendConditionRow: the QP has no row left");
  const double inv_norm = 1.0 / norm;
  qp->a.row(qp->m) = normal.transpose() * inv_norm;
  qp->b(qp->m) = (normal.dot(qp->x0) - psi) * inv_norm;
  r.norm = norm;
  r.row = qp->m++;
  return r;
}

/// Appends the force-limit rows |F_i| <= f_max_n of F = T y (T = metric_map,
/// docs/safety.md): per leg i, T_i y >= -f_max_n then -T_i y >= -f_max_n.
template <int MaxRows>
void AppendForceLimitRows(const Matrix6d& metric_map, double f_max_n, ProjectionQpN<MaxRows>* qp) {
  STEWART_CHECK(qp->m + 2 * kNumLegs <= MaxRows, "AppendForceLimitRows: too few rows left");
  for (int i = 0; i < kNumLegs; ++i) {
    qp->a.row(qp->m) = metric_map.row(i);
    qp->b(qp->m++) = -f_max_n;
    qp->a.row(qp->m) = -metric_map.row(i);
    qp->b(qp->m++) = -f_max_n;
  }
}

}  // namespace stewart::safety
