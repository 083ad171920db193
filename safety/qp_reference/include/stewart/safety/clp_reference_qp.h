#pragma once
// QP reference with COIN-OR Clp (EPL-2.0): the quadratic objective goes to
// ClpSimplex::loadQuadraticObjective and is solved by Clp's primal simplex
// for QPs (docs/safety.md: accuracy and speed measured against ALGLIB).
#include "stewart/safety/reference_qp.h"

namespace stewart::safety {

class ClpReferenceQp final : public ReferenceQpSolver {
 public:
  ProjectionStatus Solve(const ProjectionQp& qp, Vector6d* x) override;
  const char* name() const override { return "clp"; }
};

}  // namespace stewart::safety
