#pragma once
// The safety filter's per-step data, kept apart from its model the way
// Pinocchio keeps Data apart from Model: SafetyFilter holds what is fixed
// after construction (parameters, constraint set), FilterWorkspace every
// intermediate of one step (model terms, barrier intermediates, metric map,
// the QPs as posed, their solutions). Fixed-size storage only, so a step
// allocates nothing; nothing in it carries over from one step to the next.
#include "stewart/model/dynamics.h"
#include "stewart/safety/barriers.h"
#include "stewart/safety/leg_jacobian_factor.h"
#include "stewart/safety/projection_qp.h"
#include "stewart/safety/two_constraint_qp.h"
#include "stewart/safety/uncomposed_qp.h"

namespace stewart::safety {

/// Which condition groups a QP poses (the fallbacks relax one group).
enum class ConditionGroups { kAll, kPositionOnly, kVelocityOnly };

/// Which rows of the composed QP (SafetyFilter::BuildQp) hold which condition.
struct QpRows {
  int p = -1, v = -1;  ///< row of each CBF condition, -1 if left out
  /// |g~| of each posed condition: the row holds g~/|g~|, so the condition's
  /// own multiplier is the row's divided by it.
  double p_norm = 0.0, v_norm = 0.0;
  int box = 0;  ///< first force-limit row (lower, upper per leg)
};

/// One QP as posed, which row holds what, and its solution.
template <int MaxRows, typename Rows>
struct PosedQp {
  ProjectionQpN<MaxRows> qp;
  Rows rows;
  ProjectionResultN<MaxRows> result;
};
using ComposedQpData = PosedQp<kMaxQpRows, QpRows>;
using UncomposedQpData = PosedQp<kMaxUncomposedQpRows, UncomposedQpRows>;

// On a cache line of its own, so that which lines a step touches does not
// depend on where the filter holding it sits.
struct alignas(64) FilterWorkspace {
  DynamicsTerms terms;           ///< model terms at (q, qd), evaluated by Step
  BarrierIntermediates barrier;  ///< what EvaluateBarriers leaves for the solve
  Matrix6d metric_map;           ///< T (SafetyFilter::MetricMap), when a QP is posed
  TwoConstraintProblem problem;  ///< the composed conditions in y = T^-1 F
  ComposedQpData composed;       ///< force-limited variant and QP reference
  UncomposedQpData uncomposed;   ///< variant uncomposed: every row, or the position rows
  UncomposedQpData
      velocity_alone;  ///< its unlimited fallback: the velocity rows, from the position rows'
                       ///< point; its force-limited one: every row, relaxed
  LegJacobianFactor leg_jacobian;  ///< reset by each step
  /// The metric's factor L (T = H^-1 L; SafetyFilter::MetricFactor) as the
  /// metric map's computation left it this step.
  Matrix6d metric_factor;
  bool metric_factor_ready = false;  ///< reset by each step
  /// y = T^-1 F of the force-limited posing, for F = y_des_of_n.
  Vector6d y_des, y_des_of_n;
  bool y_des_ready = false;  ///< reset by each step
  /// A solve with H this step met H singular or nearly so
  /// (kMaxLegJacobianCondition): the pose is a singular configuration.
  bool leg_jacobian_degenerate = false;
};

}  // namespace stewart::safety
