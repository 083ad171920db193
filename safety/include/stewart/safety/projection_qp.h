#pragma once
// Exact solver of the small projection QP behind the force-limited filter:
//
//   min 1/2 ||x - x0||^2   s.t.  a_i^T x >= b_i,  i < m  (x in R^6, m <= 14)
//
// Goldfarb-Idnani dual active-set method with identity Hessian: start at the
// unconstrained minimum x0, add the most violated constraint, and move along
// the part of a_p orthogonal to the active normals while keeping every
// multiplier non-negative (dropping a constraint whose multiplier reaches 0).
// It terminates after finitely many active-set changes at the exact KKT
// point, or proves infeasibility (a_p depends on active normals with
// non-positive weights). Fixed-size storage: no heap allocation.
#include <array>

#include "stewart/model/types.h"

namespace stewart::safety {

constexpr int kMaxQpRows = 2 + 2 * kNumLegs;

struct ProjectionQp {
  int m = 0;
  Eigen::Matrix<double, kMaxQpRows, 6> a;  ///< rows a_i^T
  Eigen::Matrix<double, kMaxQpRows, 1> b;
  Vector6d x0 = Vector6d::Zero();
};

enum class ProjectionStatus { kOptimal, kInfeasible, kIterationLimit };

struct ProjectionResult {
  ProjectionStatus status = ProjectionStatus::kOptimal;
  Vector6d x = Vector6d::Zero();
  Eigen::Matrix<double, kMaxQpRows, 1> mu;  ///< x = x0 + sum mu_i a_i, mu >= 0
  int iterations = 0;
};

ProjectionResult SolveProjectionQp(const ProjectionQp& qp);

}  // namespace stewart::safety
