#include "stewart/safety/barriers.h"

#include <Eigen/Cholesky>

#include "stewart/safety/log_sum_exp.h"

namespace stewart::safety {

void EvaluateBarriers(const ConstraintSet& c, const Vector6d& q, const Vector6d& qd,
                      const DynamicsTerms& terms, const Vector6d& f_des, BarrierEvaluation* out) {
  BarrierEvaluation& e = *out;
  const Vector6d leg_rate = terms.H.transpose() * qd;  // ld = J_l qd, J_l = H^T
  const Vector6d generalised_force = terms.H * f_des;  // H F_des

  if (c.num_position > 0) {
    const double kinetic = 0.5 * qd.dot(terms.M * qd);
    // -qd^T (H F_des - G): the power term common to every position barrier.
    const double power = -qd.dot(generalised_force - terms.G);
    for (int i = 0; i < c.num_position; ++i) {
      const PositionBarrierSpec& s = c.position[static_cast<size_t>(i)];
      const bool axis = s.source == PositionSource::kAxis;
      const double value = axis ? q(s.index) : terms.leg_length_m(s.index);
      const double rate = axis ? qd(s.index) : leg_rate(s.index);
      const double h = s.sign * (value - s.limit);
      e.h_position[static_cast<size_t>(i)] = -kinetic + s.alpha_e * h;
      e.alpha_h_position[static_cast<size_t>(i)] = s.alpha * e.h_position[static_cast<size_t>(i)];
      e.dh_position[static_cast<size_t>(i)] = power + s.alpha_e * s.sign * rate;
    }
    e.h_pos = ComposeLogSumExp(e.alpha_h_position.data(), c.num_position, c.k_position,
                               e.w_position.data());
    double sum_alpha_w = 0.0;
    double psi = e.h_pos;
    for (int i = 0; i < c.num_position; ++i) {
      const double alpha_w =
          c.position[static_cast<size_t>(i)].alpha * e.w_position[static_cast<size_t>(i)];
      sum_alpha_w += alpha_w;
      psi += alpha_w * e.dh_position[static_cast<size_t>(i)];
    }
    e.psi_p = psi - c.position_margin;
    e.g_p = -sum_alpha_w * leg_rate;
  } else {
    e.h_pos = e.psi_p = 0.0;
    e.g_p.setZero();
  }

  if (c.num_velocity > 0) {
    const Eigen::LLT<Matrix6d> llt(terms.M);
    const Vector6d qdd_des = llt.solve(generalised_force - terms.C_qd - terms.G);
    for (int i = 0; i < c.num_velocity; ++i) {
      const VelocityBarrierSpec& s = c.velocity[static_cast<size_t>(i)];
      e.h_velocity[static_cast<size_t>(i)] = s.sign * (qd(s.axis) - s.limit);
      e.alpha_h_velocity[static_cast<size_t>(i)] = s.alpha_v * e.h_velocity[static_cast<size_t>(i)];
      e.dh_velocity[static_cast<size_t>(i)] = s.sign * qdd_des(s.axis);
    }
    e.h_vel = ComposeLogSumExp(e.alpha_h_velocity.data(), c.num_velocity, c.k_velocity,
                               e.w_velocity.data());
    Vector6d a_c = Vector6d::Zero();  // sum_i alpha_i w_i dh_v,i/dqd
    double psi = e.h_vel;
    for (int i = 0; i < c.num_velocity; ++i) {
      const VelocityBarrierSpec& s = c.velocity[static_cast<size_t>(i)];
      const double alpha_w = s.alpha_v * e.w_velocity[static_cast<size_t>(i)];
      a_c(s.axis) += alpha_w * s.sign;
      psi += alpha_w * e.dh_velocity[static_cast<size_t>(i)];
    }
    e.psi_v = psi - c.velocity_margin;
    e.g_v = terms.H.transpose() * llt.solve(a_c);
  } else {
    e.h_vel = e.psi_v = 0.0;
    e.g_v.setZero();
  }
}

}  // namespace stewart::safety
