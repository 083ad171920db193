#pragma once
// QP reference with ALGLIB's dense QP, BLEIC active-set algorithm.
// LICENCE: ALGLIB is GPL-2+. This header and its target
// (stewart_safety_qp_alglib, CMake option STEWART_WITH_ALGLIB) are an
// optional component: a binary linking it is GPL. The core library
// stewart_safety never links it.
#include "stewart/safety/reference_qp.h"
#include "stewart/safety/uncomposed_qp.h"

namespace stewart::safety {

class AlglibReferenceQp final : public ReferenceQpSolver {
 public:
  ProjectionStatus Solve(const ProjectionQp& qp, Vector6d* x) override;
  /// The un-composed QP (up to 48 rows), posed the same way.
  ProjectionStatus Solve(const UncomposedQp& qp, Vector6d* x);
  const char* name() const override { return "alglib"; }
};

}  // namespace stewart::safety
