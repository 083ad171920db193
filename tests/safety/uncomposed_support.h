#pragma once
// What the un-composed variant's tests check its output against, computed
// independently of the filter's QP: each barrier's own condition
// Psi_i(F) = alpha_i (dh_i(F) + h_i) - delta at F (from barriers.h, with the
// leg friction shift) and its normal n_i = dPsi_i/dF (with Eigen's inverse).
#include <array>
#include <cmath>
#include <random>
#include <string>

#include "safety_test_support.h"
#include "stewart/model/kinematics.h"

namespace stewart::safety::test {

struct SingleBarrierConditions {
  int num_position = 0, num_velocity = 0;
  std::array<double, kMaxPositionBarriers> psi_position{};  ///< Psi_i(F) (W)
  std::array<double, kMaxVelocityBarriers> psi_velocity{};  ///< Psi_i(F) (m/s^2)
  std::array<Vector6d, kMaxPositionBarriers> n_position;    ///< alpha_i (-H^T qd)
  std::array<Vector6d, kMaxVelocityBarriers> n_velocity;    ///< alpha_i H^T M^-1 a_i
};

inline SingleBarrierConditions EvaluateSingleBarrierConditions(const SafetyFilter& filter,
                                                               const Vector6d& q,
                                                               const Vector6d& qd,
                                                               const DynamicsTerms& terms,
                                                               const Vector6d& f) {
  const ConstraintSet& c = filter.constraints();
  BarrierEvaluation e;
  BarrierIntermediates x;
  EvaluateBarriers(c, q, qd, terms, f, filter.leg_friction_nspm(), GeneralizedDisturbance{}, &e,
                   &x);
  SingleBarrierConditions s;
  s.num_position = c.num_position;
  s.num_velocity = c.num_velocity;
  const Matrix6d h_t_m_inv = terms.H.transpose() * terms.M.inverse();
  for (size_t i = 0; i < static_cast<size_t>(c.num_position); ++i) {
    const double alpha = c.position[i].alpha;
    s.psi_position[i] = c.position_rate_per_s * e.alpha_h_position[i] + alpha * e.dh_position[i] -
                        c.position_margin;
    s.n_position[i] = -alpha * (terms.H.transpose() * qd);
  }
  for (size_t i = 0; i < static_cast<size_t>(c.num_velocity); ++i) {
    const VelocityBarrierSpec& v = c.velocity[i];
    if (!e.velocity_active[i]) {  // not in the QP: a row that always holds
      s.psi_velocity[i] = 0.0;
      s.n_velocity[i].setZero();
      continue;
    }
    s.psi_velocity[i] = c.velocity_rate_per_s * e.alpha_h_velocity[i] +
                        v.alpha_v * e.dh_velocity[i] - c.velocity_margin;
    s.n_velocity[i] = v.alpha_v * h_t_m_inv * VelocityBarrierGradient(v, terms.H);
  }
  return s;
}

// A state where one velocity barrier matters: one translation axis j moves
// toward one of its limits (position 0.1-10 mm away, velocity 0.5-5 mm/s
// below its limit) and the nominal force accelerates it further (1e-3 ..
// 1 m/s^2, log-uniform), every other axis slow, near the middle of its range
// and hardly accelerated.
using NearOneLimit = FilterInput;

inline bool DrawNearOneLimit(std::mt19937* rng, NearOneLimit* out) {
  const SafetyConfig s = RichSafetyConfig();
  const PlatformParams& platform = DefaultConfig().platform;
  std::uniform_int_distribution<int> axis_of(0, 2), side_of(0, 1);
  std::uniform_real_distribution<double> unit(-1.0, 1.0), gap_v(5e-4, 5e-3);
  // Log-uniform: the position barrier binds only within ~|qd| alpha_e / alpha
  // of its limit, and alone only when the push is below the velocity margin.
  std::uniform_real_distribution<double> log_gap_q(std::log(1e-4), std::log(1e-2)),
      log_accel(std::log(1e-3), std::log(1.0));
  const int j = axis_of(*rng);
  const double toward = side_of(*rng) == 0 ? 1.0 : -1.0;  // +1: the upper limits
  const PositionLimitConfig& p = s.position_limits[static_cast<size_t>(j)];
  const VelocityLimitConfig& v = s.velocity_limits[static_cast<size_t>(j)];
  Vector6d q = DefaultConfig().home_pose, qd;
  for (int a = 0; a < 6; ++a) {
    q(a) += (a < 3 ? 0.01 : 0.02) * unit(*rng);
    qd(a) = (a < 3 ? 1e-5 : 3e-5) * unit(*rng);
  }
  const double gap_q = std::exp(log_gap_q(*rng));
  q(j) = toward > 0 ? *p.upper - gap_q : *p.lower + gap_q;
  qd(j) = toward > 0 ? *v.upper - gap_v(*rng) : *v.lower + gap_v(*rng);
  const Vector6d l = InverseKinematics(platform, q);
  const double margin = s.leg_stroke.margin_m;
  if (!PoseInWorkspace(platform, q) || l.minCoeff() < platform.leg_min_length_m + margin + 0.01 ||
      l.maxCoeff() > platform.leg_max_length_m - margin - 0.01) {
    return false;
  }
  out->q = q;
  out->qd = qd;
  out->terms = EvaluateDynamics(platform, q, qd);
  Vector6d qdd;
  // The other axes' accelerations stay below their velocity margins (a
  // velocity row allows qdd up to alpha h_v, ~0.01 m/s^2 here).
  for (int a = 0; a < 6; ++a) qdd(a) = 2e-3 * unit(*rng);
  qdd(j) = toward * std::exp(log_accel(*rng));
  out->f_des = InverseDynamics(out->terms, qdd);
  return true;
}

// A state where the position barrier of axis j binds, alone or with its
// velocity barrier: the axis moves toward its limit at 2-10 mm/s, pushed
// further by a (1e-4 .. 0.1 m/s^2), placed so that the position condition is
// violated by a small amount even at the push the velocity barrier allows.
// The correction then stays ~1e-3 m/s^2 or below, far inside every other
// barrier's margin (a stronger braking demand would meet the opposite
// velocity limit's: alpha_v (v_max + |qd|) ~ 0.03 m/s^2 here).
inline bool DrawNearPositionLimit(const SafetyFilter& filter, double other_speed, std::mt19937* rng,
                                  NearOneLimit* out) {
  const SafetyConfig s = RichSafetyConfig();
  const PlatformParams& platform = DefaultConfig().platform;
  std::uniform_int_distribution<int> axis_of(0, 2), side_of(0, 1);
  std::uniform_real_distribution<double> unit(-1.0, 1.0), speed(2e-3, 1e-2),
      log_push(std::log(1e-4), std::log(0.1)), log_excess(std::log(1e-6), std::log(1e-3));
  const int j = axis_of(*rng);
  const double toward = side_of(*rng) == 0 ? 1.0 : -1.0;
  const PositionLimitConfig& p = s.position_limits[static_cast<size_t>(j)];
  const VelocityLimitConfig& v = s.velocity_limits[static_cast<size_t>(j)];
  const std::string name = std::string(1, "xyz"[j]) + (toward > 0 ? "_upper" : "_lower");
  int barrier = -1;
  for (int i = 0; i < filter.constraints().num_position; ++i) {
    if (filter.constraints().position[static_cast<size_t>(i)].name == name) barrier = i;
  }
  if (barrier < 0) return false;
  const double v_j = speed(*rng);
  const double push = std::exp(log_push(*rng));
  const double excess_mps2 = std::exp(log_excess(*rng));
  // The push left after the velocity barrier: qdd_j <= alpha_v (v_max - |qd_j|).
  const double v_max = toward > 0 ? *v.upper : -*v.lower;
  const double push_after = std::min(push, v.alpha_v * (v_max - v_j));
  Vector6d q = DefaultConfig().home_pose, qd, qdd;
  for (int a = 0; a < 6; ++a) {
    q(a) += (a < 3 ? 0.01 : 0.02) * unit(*rng);
    qd(a) = (a < 3 ? 1.0 : 3.0) * other_speed * unit(*rng);
    qdd(a) = 2e-4 * unit(*rng);
  }
  qd(j) = toward * v_j;
  // Psi_i is affine in the gap to the limit (slope alpha alpha_e) for fixed
  // model terms: two secant steps from the middle of the range place it at
  // -alpha m_jj |qd_j| excess with the push the velocity barrier leaves.
  double gap = 0.5 * (*p.upper - *p.lower);
  for (int iteration = 0; iteration < 3; ++iteration) {
    q(j) = toward > 0 ? *p.upper - gap : *p.lower + gap;
    const DynamicsTerms terms = EvaluateDynamics(platform, q, qd);
    Vector6d qdd_after = qdd;
    qdd_after(j) = toward * push_after;
    const double psi =
        EvaluateSingleBarrierConditions(filter, q, qd, terms, InverseDynamics(terms, qdd_after))
            .psi_position[static_cast<size_t>(barrier)];
    gap -= (psi + p.alpha * terms.M(j, j) * v_j * excess_mps2) / (p.alpha * p.alpha_e);
  }
  q(j) = toward > 0 ? *p.upper - gap : *p.lower + gap;
  const Vector6d l = InverseKinematics(platform, q);
  const double margin = s.leg_stroke.margin_m;
  if (gap <= 0.0 || !PoseInWorkspace(platform, q) ||
      l.minCoeff() < platform.leg_min_length_m + margin + 0.01 ||
      l.maxCoeff() > platform.leg_max_length_m - margin - 0.01) {
    return false;
  }
  out->q = q;
  out->qd = qd;
  out->terms = EvaluateDynamics(platform, q, qd);
  qdd(j) = toward * push;
  out->f_des = InverseDynamics(out->terms, qdd);
  return true;
}

}  // namespace stewart::safety::test
