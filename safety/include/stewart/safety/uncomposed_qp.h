#pragma once
// The un-composed QP (variant `uncomposed`, docs/safety.md "The un-composed
// QP"): every barrier its own condition, no Log-Sum-Exp. The k -> infinity
// limit of one group's composed condition with a single barrier i active is
//
//   Psi_i(F) = alpha_i (dh_i(F) + h_i) - delta_group >= 0,
//
// affine in F with normal alpha_i g_i: g_i = -H^T qd for every position
// barrier (the same direction for all of them), g_i = H^T M^-1 a_i for
// velocity barrier i (a_i = dh_v,i/dqd). The filter solves
//
//   min (F - F_des)^T W (F - F_des)  s.t.  Psi_i(F) >= 0 for every barrier
//                                          [, |F_i| <= F_max]
//
// exactly, with the dual active-set solver of projection_qp.h, posed like
// SafetyFilter::BuildQp in the metric's coordinates y = T^-1 F with unit-normal
// rows T^T alpha_i g_i / |T^T alpha_i g_i|.
#include <array>

#include "stewart/safety/barriers.h"
#include "stewart/safety/constraint_set.h"
#include "stewart/safety/projection_qp.h"

namespace stewart::safety {

/// Every position and velocity barrier a row, plus the force limits.
constexpr int kMaxUncomposedQpRows = kMaxPositionBarriers + kMaxVelocityBarriers + 2 * kNumLegs;

using UncomposedQp = ProjectionQpN<kMaxUncomposedQpRows>;
using UncomposedQpResult = ProjectionResultN<kMaxUncomposedQpRows>;

extern template ProjectionResultN<kMaxUncomposedQpRows> SolveProjectionQp(
    const ProjectionQpN<kMaxUncomposedQpRows>&);

/// Psi_i at the nominal force of position barrier k: alpha_k (dh_k + gamma_p
/// h_k) - delta_p (W), with dh_k at F_des plus friction (barriers.h).
inline double OwnPositionCondition(const ConstraintSet& c, const BarrierEvaluation& b, int k) {
  const size_t i = static_cast<size_t>(k);
  return c.position_rate_per_s * b.alpha_h_position[i] + c.position[i].alpha * b.dh_position[i] -
         c.position_margin;
}
/// The same for velocity barrier k (m/s^2).
inline double OwnVelocityCondition(const ConstraintSet& c, const BarrierEvaluation& b, int k) {
  const size_t i = static_cast<size_t>(k);
  return c.velocity_rate_per_s * b.alpha_h_velocity[i] + c.velocity[i].alpha_v * b.dh_velocity[i] -
         c.velocity_margin;
}

/// Which QP row holds which barrier (SafetyFilter::BuildUncomposedQp).
struct UncomposedQpRows {
  /// Row of barrier i, -1 when left out (dropped, or a zero normal: then the
  /// condition does not depend on F and is either met or makes the QP
  /// unposable).
  std::array<int, kMaxPositionBarriers> position_row{};
  std::array<int, kMaxVelocityBarriers> velocity_row{};
  /// |T^T alpha_i g_i| of each posed row: the row holds the normal divided by
  /// it, so the condition's own multiplier is the row's divided by it.
  std::array<double, kMaxPositionBarriers> position_norm{};
  std::array<double, kMaxVelocityBarriers> velocity_norm{};
  int box = 0;  ///< first force-limit row (lower, upper per leg)
};

}  // namespace stewart::safety
