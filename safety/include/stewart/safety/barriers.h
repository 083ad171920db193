#pragma once
// The two composed CBF conditions, affine in the leg forces F (N):
//
//   Psi_p(F) = psi_p + g_p^T (F - F_des) >= 0   (position group, energy-based)
//   Psi_v(F) = psi_v + g_v^T (F - F_des) >= 0   (velocity group)
//
// Position barrier i (NOTES.md, paper eqs. 7-11), units J and W:
//   h_D,i  = -1/2 qd^T M qd + alpha_e,i h_i(q)
//   dh_D,i = -qd^T (H F - G) + alpha_e,i (dh_i/dq) qd
// Velocity barrier i (paper eqs. 12-14), a_i = dh_v,i/dqd = sign_i e_j:
//   dh_v,i = a_i^T M^-1 (H F - C qd - G)
// Group composition (alpha-weighted LSE, log_sum_exp.h), per group:
//   h_c = LSE_k(alpha_i h_i),  psi = sum_i alpha_i w_i dh_i(F_des) + h_c,
//   g = sum_i alpha_i w_i dh_i/dF
// so g_p = (sum_i alpha_i w_i) (-H^T qd) and g_v = H^T M^-1 sum_i alpha_i w_i a_i.
#include <array>

#include "stewart/model/dynamics.h"
#include "stewart/safety/constraint_set.h"

namespace stewart::safety {

struct BarrierEvaluation {
  // Per barrier (first num_* entries valid).
  std::array<double, kMaxPositionBarriers> h_position{};        ///< h_D,i (J)
  std::array<double, kMaxPositionBarriers> alpha_h_position{};  ///< alpha_i h_D,i (W)
  std::array<double, kMaxPositionBarriers> w_position{};        ///< LSE weights
  std::array<double, kMaxPositionBarriers> dh_position{};       ///< dh_D,i at F_des (W)
  std::array<double, kMaxVelocityBarriers> h_velocity{};        ///< h_v,i (m/s)
  std::array<double, kMaxVelocityBarriers> alpha_h_velocity{};  ///< alpha_i h_v,i (m/s^2)
  std::array<double, kMaxVelocityBarriers> w_velocity{};
  std::array<double, kMaxVelocityBarriers> dh_velocity{};  ///< dh_v,i at F_des (m/s^2)
  // Composed (zero when the group is empty).
  double h_pos = 0.0;               ///< composed position barrier (W)
  double h_vel = 0.0;               ///< composed velocity barrier (m/s^2)
  double psi_p = 0.0;               ///< Psi_p(F_des) - position robust margin (W)
  double psi_v = 0.0;               ///< Psi_v(F_des) - velocity robust margin (m/s^2)
  Vector6d g_p = Vector6d::Zero();  ///< dPsi_p/dF (W/N = m/s)
  Vector6d g_v = Vector6d::Zero();  ///< dPsi_v/dF (m/s^2 per N)
  /// T of the correction metric (SafetyFilter; docs/safety.md): with
  /// F = T y the cost (F - F_des)^T W (F - F_des) is ||y - y_des||^2, W^-1 = T T^T.
  /// Identity for the force metric; H^-1 L_M (M = L_M L_M^T) for the
  /// acceleration metric.
  Matrix6d metric_map = Matrix6d::Identity();
};

/// Evaluates every barrier and the two composed conditions at (q, qd, F_des)
/// from the model terms at (q, qd). No heap allocation.
void EvaluateBarriers(const ConstraintSet& constraints, const Vector6d& q, const Vector6d& qd,
                      const DynamicsTerms& terms, const Vector6d& f_des, BarrierEvaluation* out);

}  // namespace stewart::safety
