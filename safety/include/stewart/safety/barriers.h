#pragma once
// The two composed CBF conditions, affine in the leg forces F (N):
//
//   Psi_p(F) = psi_p + g_p^T (F - F_des) >= 0   (position group, energy-based)
//   Psi_v(F) = psi_v + g_v^T (F - F_des) >= 0   (velocity group)
//
// Position barrier i (NOTES.md, paper eqs. 7-11), units J and W:
//   h_D,i  = -1/2 qd^T M qd + alpha_e,i h_i(q)
//   dh_D,i = -qd^T (H F - G) + alpha_e,i (dh_i/dq) qd
// Velocity barrier i (paper eqs. 12-14), a_i = dh_v,i/dqd = sign_i e_j (or
// sign_i H(:, i) for a leg's recovery barrier, below):
//   dh_v,i = a_i^T M^-1 (H F - C qd - G)
// Group composition (alpha-weighted LSE, log_sum_exp.h), per group:
//   h_c = LSE_k(alpha_i h_i),  psi = sum_i alpha_i w_i dh_i(F_des) + gamma h_c,
//   g = sum_i alpha_i w_i dh_i/dF
// so g_p = (sum_i alpha_i w_i) (-H^T qd) and g_v = H^T M^-1 sum_i alpha_i w_i a_i.
//
// Model error (docs/safety.md "Model error"): with the disturbance estimate
// d^ of M qdd + C qd + G = H F + d (model/disturbance.h), H F becomes
// H F + d^ above, and each dh_i is taken at the worst d within k_sigma
// standard deviations of d^ (entry by entry, so for any correlation):
//   dh_D,i -= k_sigma sum_j |qd_j| sigma_j,
//   dh_v,i -= k_sigma sum_j |(M^-1 a_i)_j| sigma_j
// (except a leg's recovery barrier: d^ alone, barriers.cc says why).
// Recovery barrier of a position limit (constraint_set.h), velocity group:
//   axis j: h_r = sign qd_j + phi(h(q)), dh_r = sign qdd_j + phi' sign qd_j
//   leg i:  h_r = sign ld_i + phi(h(l)),
//           dh_r = sign (H(:, i)^T qdd + (J_l-dot qd)_i) + phi' sign ld_i
// (a_i = sign H(:, i), so g_v and the worst case over d take the same form),
// a leg's in the group only while its leg is beyond the band (velocity_active).
#include <array>

#include "stewart/model/disturbance.h"
#include "stewart/model/dynamics.h"
#include "stewart/model/linear_algebra6.h"
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
  /// Whether velocity barrier i is in the group this step: a leg's recovery
  /// barrier only while its leg is beyond its band (its h(l) < 0); inside,
  /// the leg's energy barrier guards it and the recovery barrier is left out
  /// (w_i = 0, no condition, no QP row), as if it did not exist.
  std::array<bool, kMaxVelocityBarriers> velocity_active{};
  // Composed (zero when the group is empty).
  double h_pos = 0.0;  ///< composed position barrier (W)
  double h_vel = 0.0;  ///< composed velocity barrier (m/s^2)
  double psi_p = 0.0;  ///< Psi_p(F_des) - position robust margin (W)
  double psi_v = 0.0;  ///< Psi_v(F_des) - velocity robust margin (m/s^2)
  /// Some axis position barrier has h(q) < 0 and recovery barriers exist: the
  /// position group's condition is left out (its F gradient vanishes at rest,
  /// so it would demand unbounded forces) and the recovery barriers steer back.
  bool outside_position_set = false;
  /// Some velocity limit or (inside) position limit is exceeded: h < 0.
  bool outside_safe_set = false;
  /// Of those: some velocity limit (not a recovery barrier) is exceeded, or
  /// some position limit without a recovery barrier to steer back is. Outside
  /// the set but neither of these, the recovery barriers steer back in (the
  /// supervisor arms there).
  bool outside_unrecoverably = false;
  Vector6d g_p = Vector6d::Zero();  ///< dPsi_p/dF (W/N = m/s)
  Vector6d g_v = Vector6d::Zero();  ///< dPsi_v/dF (m/s^2 per N)
};

/// What EvaluateBarriers computes on the way and the filter needs again, so
/// that nothing is evaluated twice per step: the factor of M, H^T qd, M qd
/// and the two composed directions (g_p = -s_p ld, g_v = H^T M^-1 a_c).
struct BarrierIntermediates {
  Cholesky6 inertia;           ///< M = L D L^T (valid iff inertia_valid)
  bool inertia_valid = false;  ///< M was positive definite
  Vector6d leg_rate;           ///< ld = H^T qd (m/s)
  Vector6d m_qd;               ///< M qd
  double qd_m_qd = 0.0;        ///< qd^T M qd = twice the kinetic energy (J)
  double s_p = 0.0;            ///< sum_i alpha_i w_i of the position group (1/s)
  Vector6d a_c;                ///< sum_i alpha_i w_i dh_v,i/dqd of the velocity group
  Vector6d m_inv_a_c;          ///< M^-1 a_c (only with velocity barriers)
  Matrix6d m_inv;              ///< M^-1 (only with velocity barriers)
};

/// Evaluates every barrier and the two composed conditions at (q, qd, F_des)
/// from the model terms at (q, qd). No heap allocation.
void EvaluateBarriers(const ConstraintSet& constraints, const Vector6d& q, const Vector6d& qd,
                      const DynamicsTerms& terms, const Vector6d& f_des, BarrierEvaluation* out);

/// The same, with the conditions evaluated at the net force the legs push,
/// F_des + LegViscousFriction(leg_friction_nspm, H^T qd), plus the
/// disturbance estimate, and the intermediates returned. Psi is NaN (so the
/// caller rejects the step) when velocity barriers exist and M is not
/// positive definite.
void EvaluateBarriers(const ConstraintSet& constraints, const Vector6d& q, const Vector6d& qd,
                      const DynamicsTerms& terms, const Vector6d& f_des, double leg_friction_nspm,
                      const GeneralizedDisturbance& disturbance, BarrierEvaluation* out,
                      BarrierIntermediates* intermediates);

/// The part of the intermediates that does not depend on F_des (the factor
/// of M, H^T qd), for a caller that needs it first (the filter's per-period
/// bound on F_des, nominal_bound.h).
void PrepareBarrierIntermediates(const DynamicsTerms& terms, const Vector6d& qd,
                                 BarrierIntermediates* intermediates);

/// EvaluateBarriers with `intermediates` already prepared by
/// PrepareBarrierIntermediates at the same (terms, qd): M is factored once.
void EvaluatePreparedBarriers(const ConstraintSet& constraints, const Vector6d& q,
                              const Vector6d& qd, const DynamicsTerms& terms, const Vector6d& f_des,
                              double leg_friction_nspm, const GeneralizedDisturbance& disturbance,
                              BarrierEvaluation* out, BarrierIntermediates* intermediates);

}  // namespace stewart::safety
