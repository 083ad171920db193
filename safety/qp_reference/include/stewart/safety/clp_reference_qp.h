#pragma once
// QP reference with COIN-OR Clp (EPL-2.0): Clp's interior point (barrier) on
// the QP finds the active set; the answer is the exact projection on that
// set, returned only when the KKT conditions certify it. Clp's dual simplex
// on the rows decides infeasibility when no certified answer comes out
// (docs/safety.md "QP reference: ALGLIB vs Clp": why not its QP simplex).
#include "stewart/safety/reference_qp.h"
#include "stewart/safety/uncomposed_qp.h"

namespace stewart::safety {

class ClpReferenceQp final : public ReferenceQpSolver {
 public:
  ProjectionStatus Solve(const ProjectionQp& qp, Vector6d* x) override;
  /// The un-composed QP (kMaxUncomposedQpRows rows), posed the same way.
  ProjectionStatus Solve(const UncomposedQp& qp, Vector6d* x);
  const char* name() const override { return "clp"; }
};

}  // namespace stewart::safety
