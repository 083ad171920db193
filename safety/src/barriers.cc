#include "stewart/safety/barriers.h"

#include <cmath>

#include "stewart/common/check.h"
#include "stewart/safety/log_sum_exp.h"

namespace stewart::safety {

void EvaluateBarriers(const ConstraintSet& c, const Vector6d& q, const Vector6d& qd,
                      const DynamicsTerms& terms, const Vector6d& f_des, BarrierEvaluation* out) {
  BarrierIntermediates unused;
  EvaluateBarriers(c, q, qd, terms, f_des, 0.0, GeneralizedDisturbance{}, out, &unused);
}

void PrepareBarrierIntermediates(const DynamicsTerms& terms, const Vector6d& qd,
                                 BarrierIntermediates* x) {
  x->leg_rate.noalias() = terms.H.transpose() * qd;  // ld = J_l qd, J_l = H^T
  // One factor of M per step, shared by the velocity group, the acceleration
  // metric and the per-period bound (SafetyFilter).
  x->inertia_valid = x->inertia.Compute(terms.M);
}

void EvaluateBarriers(const ConstraintSet& c, const Vector6d& q, const Vector6d& qd,
                      const DynamicsTerms& terms, const Vector6d& f_des, double leg_friction_nspm,
                      const GeneralizedDisturbance& disturbance, BarrierEvaluation* out,
                      BarrierIntermediates* x) {
  PrepareBarrierIntermediates(terms, qd, x);
  EvaluatePreparedBarriers(c, q, qd, terms, f_des, leg_friction_nspm, disturbance, out, x);
}

void EvaluatePreparedBarriers(const ConstraintSet& c, const Vector6d& q, const Vector6d& qd,
                              const DynamicsTerms& terms, const Vector6d& f_des,
                              double leg_friction_nspm, const GeneralizedDisturbance& disturbance,
                              BarrierEvaluation* out, BarrierIntermediates* x) {
  // The per-barrier arrays hold kMax* entries (a hand-built ConstraintSet
  // skips BuildConstraintSet's capacity check).
  STEWART_CHECK(static_cast<unsigned>(c.num_position) <= kMaxPositionBarriers &&
                    static_cast<unsigned>(c.num_velocity) <= kMaxVelocityBarriers,
                "EvaluateBarriers: more barriers than their arrays hold");
  BarrierEvaluation& e = *out;
  // The conditions hold for what the legs really push: F + friction.
  const Vector6d f_net = f_des + LegViscousFriction(leg_friction_nspm, x->leg_rate);
  Vector6d generalised_force;  // H F_net + d^
  generalised_force.noalias() = terms.H * f_net;
  generalised_force += disturbance.force_n;
  // k_sigma sigma_j: how far each entry of d may be from d^.
  const Vector6d d_bound = c.disturbance_sigma * disturbance.std_n;
  const bool robust = (d_bound.array() > 0.0).any();
  e.outside_position_set = false;
  e.outside_safe_set = false;
  e.outside_unrecoverably = false;
  x->m_qd.noalias() = terms.M * qd;
  x->qd_m_qd = qd.dot(x->m_qd);

  if (c.num_position > 0) {
    const double kinetic = 0.5 * x->qd_m_qd;
    // -qd^T (H F_des + d^ - G): the power term common to every position
    // barrier, at its worst over the disturbance's uncertainty.
    const double power =
        -qd.dot(generalised_force - terms.G) - (robust ? qd.cwiseAbs().dot(d_bound) : 0.0);
    for (int i = 0; i < c.num_position; ++i) {
      const size_t k = static_cast<size_t>(i);
      const PositionBarrierSpec& s = c.position[k];
      const bool axis = s.source == PositionSource::kAxis;
      const double value = axis ? q(s.index) : terms.leg_length_m(s.index);
      const double rate = axis ? qd(s.index) : x->leg_rate(s.index);
      const double h = s.sign * (value - s.limit);
      if (h < 0.0) {
        e.outside_safe_set = true;
        // Its recovery barrier steers back (axis limits have one whenever
        // any exist, the legs' strokes when has_leg_recovery).
        const bool recovers = axis ? c.has_recovery : c.has_leg_recovery;
        e.outside_position_set = e.outside_position_set || recovers;
        e.outside_unrecoverably = e.outside_unrecoverably || !recovers;
      }
      e.h_position[k] = -kinetic + s.alpha_e * h;
      e.alpha_h_position[k] = s.alpha * e.h_position[k];
      e.dh_position[k] = power + s.alpha_e * s.sign * rate;
    }
    e.h_pos = ComposeLogSumExp(e.alpha_h_position.data(), c.num_position, c.k_position,
                               e.w_position.data());
    double sum_alpha_w = 0.0;
    double psi = c.position_rate_per_s * e.h_pos;
    for (int i = 0; i < c.num_position; ++i) {
      const size_t k = static_cast<size_t>(i);
      const double alpha_w = c.position[k].alpha * e.w_position[k];
      sum_alpha_w += alpha_w;
      psi += alpha_w * e.dh_position[k];
    }
    e.psi_p = psi - c.position_margin;
    x->s_p = sum_alpha_w;
    e.g_p = -sum_alpha_w * x->leg_rate;
  } else {
    e.h_pos = e.psi_p = 0.0;
    x->s_p = 0.0;
    e.g_p.setZero();
  }

  x->a_c.setZero();
  if (c.num_velocity > 0) {
    std::array<double, kMaxVelocityBarriers> recovery_slope;  // dphi/dh (1/s)
    if (!x->inertia_valid) {
      // M^-1 does not exist: no velocity condition can be evaluated.
      e.h_vel = e.psi_v = NAN;
      e.g_v.setConstant(NAN);
      x->m_inv_a_c.setConstant(NAN);
      return;
    }
    // r_i = a_i^T qd / sign_i: qd_j for an axis, ld_i for a leg.
    auto rate_of = [&](const VelocityBarrierSpec& s) {
      return s.source == PositionSource::kAxis ? qd(s.index) : x->leg_rate(s.index);
    };
    // The active barriers' alpha h, packed for the composition.
    std::array<double, kMaxVelocityBarriers> packed_alpha_h;
    std::array<double, kMaxVelocityBarriers> packed_w;
    int num_active = 0;
    for (int i = 0; i < c.num_velocity; ++i) {
      const size_t k = static_cast<size_t>(i);
      const VelocityBarrierSpec& s = c.velocity[k];
      e.velocity_active[k] = true;
      if (s.recovery_of < 0) {
        e.h_velocity[k] = s.sign * (rate_of(s) - s.limit);
        if (e.h_velocity[k] < 0.0) e.outside_safe_set = e.outside_unrecoverably = true;
      } else {
        const PositionBarrierSpec& p = c.position[static_cast<size_t>(s.recovery_of)];
        const double value =
            p.source == PositionSource::kAxis ? q(p.index) : terms.leg_length_m(p.index);
        double phi = 0.0, dphi_dh = 0.0;
        const double h_position = p.sign * (value - p.limit);
        RecoveryTarget(s, h_position, &phi, &dphi_dh);
        e.h_velocity[k] = s.sign * rate_of(s) + phi;
        recovery_slope[k] = dphi_dh;
        // Inside its band a leg's energy barrier guards it, and every run
        // that keeps its legs there stays what it was without the recovery
        // barriers (always in the group they made 455 of 1000 exact random
        // runs infeasible at times, docs/safety.md).
        e.velocity_active[k] = s.source == PositionSource::kAxis || h_position < 0.0;
      }
      e.alpha_h_velocity[k] = s.alpha_v * e.h_velocity[k];
      if (e.velocity_active[k]) {
        packed_alpha_h[static_cast<size_t>(num_active++)] = e.alpha_h_velocity[k];
      }
    }
    if (num_active == 0) {
      // Only legs' recovery barriers, every leg inside its band: no group.
      e.w_velocity.fill(0.0);
      e.h_vel = e.psi_v = 0.0;
      x->m_inv_a_c.setZero();
      e.g_v.setZero();
      return;
    }
    e.h_vel = ComposeLogSumExp(packed_alpha_h.data(), num_active, c.k_velocity, packed_w.data());
    for (int i = 0, j = 0; i < c.num_velocity; ++i) {
      const size_t k = static_cast<size_t>(i);
      e.w_velocity[k] = e.velocity_active[k] ? packed_w[static_cast<size_t>(j++)] : 0.0;
    }
    for (int i = 0; i < c.num_velocity; ++i) {
      const size_t k = static_cast<size_t>(i);
      const VelocityBarrierSpec& s = c.velocity[k];
      if (!e.velocity_active[k]) continue;
      const double weight = s.alpha_v * e.w_velocity[k] * s.sign;
      if (s.source == PositionSource::kAxis) {
        x->a_c(s.index) += weight;
      } else {
        x->a_c += weight * terms.H.col(s.index);
      }
    }
    // qdd_des = M^-1 (H F_des + d^ - C qd - G), M^-1 a_c and M^-1 in one pass.
    Rhs6<8> rhs;
    rhs.col(0) = generalised_force - terms.C_qd - terms.G;
    rhs.col(1) = x->a_c;
    rhs.rightCols<6>().setIdentity();
    x->inertia.SolveInPlace<8>(&rhs);
    x->m_inv = rhs.rightCols<6>();
    // dh_v,i/dd = a_i^T M^-1: the worst case per axis, sum_j |(M^-1)_(axis, j)|
    // sigma_j; a leg's row is H(:, i)^T M^-1, its worst case computed apart.
    Vector6d axis_bound = Vector6d::Zero();
    if (robust) axis_bound.noalias() = x->m_inv.cwiseAbs() * d_bound;
    double psi = c.velocity_rate_per_s * e.h_vel;
    for (int i = 0; i < c.num_velocity; ++i) {
      const size_t k = static_cast<size_t>(i);
      const VelocityBarrierSpec& s = c.velocity[k];
      if (!e.velocity_active[k]) {
        e.dh_velocity[k] = 0.0;
        continue;
      }
      if (s.source == PositionSource::kAxis) {
        e.dh_velocity[k] = s.sign * rhs(s.index, 0) - axis_bound(s.index);
      } else {
        // Ldd_i = H(:, i)^T qdd + (J_l-dot qd)_i.
        const auto column = terms.H.col(s.index);
        const double leg_accel = column.dot(rhs.col(0)) + terms.leg_bias_accel_mps2(s.index);
        // d^ but not its worst case: through the leg's lever arm a torque's
        // uncertainty is tens of m/s^2 of leg acceleration on the light
        // platform, and asking for that outward conflicts with zd's limit
        // (measured: a pushed platform stayed 4 mm beyond, infeasible
        // throughout; docs/safety.md). The recovery barrier steers back; the
        // energy barrier is the leg's invariance.
        e.dh_velocity[k] = s.sign * leg_accel;
      }
      if (s.recovery_of >= 0) e.dh_velocity[k] += recovery_slope[k] * s.sign * rate_of(s);
      psi += s.alpha_v * e.w_velocity[k] * e.dh_velocity[k];
    }
    e.psi_v = psi - c.velocity_margin;
    x->m_inv_a_c = rhs.col(1);
    e.g_v.noalias() = terms.H.transpose() * x->m_inv_a_c;
  } else {
    e.h_vel = e.psi_v = 0.0;
    x->m_inv_a_c.setZero();
    e.g_v.setZero();
  }
}

}  // namespace stewart::safety
