#pragma once
// Interface of an external QP solver used as the filter's reference
// (variant "qp"). Implementations live in separate targets so the core
// library links no solver: stewart_safety_qp_clp (Clp, EPL-2.0) and the
// optional stewart_safety_qp_alglib (ALGLIB, GPL-2+).
#include "stewart/model/types.h"
#include "stewart/safety/projection_qp.h"

namespace stewart::safety {

class ReferenceQpSolver {
 public:
  virtual ~ReferenceQpSolver() = default;
  /// Solves min ||x - x0||^2 s.t. a_i^T x >= b_i exactly as posed in `qp`;
  /// returns kInfeasible when the solver reports no solution.
  virtual ProjectionStatus Solve(const ProjectionQp& qp, Vector6d* x) = 0;
  virtual const char* name() const = 0;
};

}  // namespace stewart::safety
