#pragma once
// The filter's constraints, built once from the config (docs/safety.md).
//
// Position constraints h(q) >= 0 (m or rad, or m of leg length):
//   axis j:  h = sign (q_j - limit),   dh/dq = sign e_j^T
//   leg i:   h = sign (l_i - limit),   dh/dq = sign J_l(i,:)   (limit = l_max - margin
//                                                               or l_min + margin)
// with sign = -1 for an upper and +1 for a lower limit. Velocity constraints
// h_v(qd) = sign (qd_j - limit) >= 0 (m/s or rad/s). Recovery constraints,
// one per position limit (velocity group, docs/safety.md "Outside the safe
// set"): h_r = sign r + phi(h(q)) >= 0 (m/s) with r the rate of the limited
// quantity (qd_j for an axis, the leg speed ld_i = J_l(i,:) qd for a leg),
// phi(h) = kappa h inside (h >= 0) and v_r tanh(kappa h / v_r) outside, so
// the speed back into the set stays below v_r: half the axis's smallest
// velocity limit, and for a leg half the smallest velocity limit of any
// translational axis.
#include <array>
#include <cmath>
#include <string>

#include "stewart/model/platform_params.h"
#include "stewart/model/types.h"
#include "stewart/safety/safety_config.h"

namespace stewart::safety {

/// Capacity: a lower and an upper limit per axis, and per leg.
constexpr int kMaxPositionBarriers = 2 * kNumAxes + 2 * kNumLegs;
/// Velocity limits and the recovery barriers of the position limits.
constexpr int kMaxVelocityBarriers = 4 * kNumAxes + 2 * kNumLegs;

enum class PositionSource { kAxis, kLegLength };

struct PositionBarrierSpec {
  PositionSource source = PositionSource::kAxis;
  int index = 0;         ///< axis of q, or leg
  double sign = -1.0;    ///< -1 upper limit, +1 lower limit
  double limit = 0.0;    ///< m or rad
  double alpha_e = 1.0;  ///< energy weight (N or N m per rad: J per unit of h)
  double alpha = 1.0;    ///< class-K gain (1/s)
  std::string name;      ///< e.g. "x_upper", "leg3_lower"
};

/// h_v = sign r + (limit or phi) with r = a^T qd, a = dh_v/dqd: sign e_j for
/// an axis, sign J_l(i,:)^T = sign H(:, i) for a leg (a leg's only velocity
/// barrier is its stroke's recovery barrier).
struct VelocityBarrierSpec {
  PositionSource source = PositionSource::kAxis;
  int index = 0;  ///< axis of qd, or leg
  double sign = -1.0;
  double limit = 0.0;    ///< m/s or rad/s (unused by a recovery barrier)
  double alpha_v = 1.0;  ///< class-K gain (1/s)
  std::string name;      ///< e.g. "zd_upper", "z_upper_recovery", "leg3_lower_recovery"
  /// A recovery barrier: the index of its position barrier, whose h(q) it
  /// reads (same source and index); -1 for a velocity limit.
  int recovery_of = -1;
  double recovery_gain_per_s = 0.0;  ///< kappa (1/s)
  /// v_r (m/s or rad/s); 0: no velocity limit to stay within, phi stays linear.
  double recovery_speed = 0.0;
};

/// a_i = dh_v,i/dqd (module comment): sign e_j, or sign H(:, i) for a leg.
inline Vector6d VelocityBarrierGradient(const VelocityBarrierSpec& s, const Matrix6d& H) {
  if (s.source == PositionSource::kLegLength) return s.sign * H.col(s.index);
  return s.sign * Vector6d::Unit(s.index);
}

/// phi(h) of a recovery barrier and its derivative dphi/dh.
inline void RecoveryTarget(const VelocityBarrierSpec& s, double h, double* phi, double* dphi_dh);

struct ConstraintSet {
  int num_position = 0;
  int num_velocity = 0;
  std::array<PositionBarrierSpec, kMaxPositionBarriers> position;
  std::array<VelocityBarrierSpec, kMaxVelocityBarriers> velocity;
  double k_position = 1.0;  ///< LSE sharpness of the position group (1/W)
  double k_velocity = 1.0;  ///< LSE sharpness of the velocity group (s^2/m)
  /// Subtracted from psi_p (W) and psi_v (m/s^2): robustness margins.
  double position_margin = 0.0;
  double velocity_margin = 0.0;
  /// k_sigma: every barrier derivative is taken at the worst disturbance
  /// within this many standard deviations of the estimate (barriers.h).
  double disturbance_sigma = 0.0;
  bool has_recovery = false;  ///< recovery barriers are in the velocity group
  /// The leg-stroke barriers have recovery barriers too (leg_stroke enabled
  /// and recovery_gain_per_s > 0).
  bool has_leg_recovery = false;
  /// gamma of each group's condition Psi_c = dh_c + gamma h_c (1/s; the
  /// paper's is 1): a condition missing an acceleration error e leaves the
  /// composed barrier at about -e / gamma (docs/safety.md "Model error").
  double position_rate_per_s = 1.0;
  double velocity_rate_per_s = 1.0;
  /// How far each axis position limit was drawn in for the joints'
  /// tolerance (m, rad): the pose error's worst case over the limit faces
  /// (JointToleranceMargin). Already in the specs' limits.
  Vector6d joint_tolerance_margin = Vector6d::Zero();
};

inline void RecoveryTarget(const VelocityBarrierSpec& s, double h, double* phi, double* dphi_dh) {
  const double kappa = s.recovery_gain_per_s;
  if (h >= 0.0 || !(s.recovery_speed > 0.0)) {
    *phi = kappa * h;
    *dphi_dh = kappa;
    return;
  }
  const double t = std::tanh(kappa * h / s.recovery_speed);
  *phi = s.recovery_speed * t;
  *dphi_dh = kappa * (1.0 - t * t);
}

/// The margin the axis position limits keep for the joints' tolerance, per
/// axis (m, rad): the largest PoseErrorBound over the poses of a grid whose
/// every translational axis takes its home value and its limits (an axis
/// with one limit also the limit mirrored about home), at the home attitude,
/// the poses outside the leg stroke left out. Zero without a tolerance.
Vector6d JointToleranceMargin(const PlatformParams& platform, const SafetyConfig& safety);

/// Throws InputError (a std::invalid_argument naming the config key) when the
/// config holds more constraints than the capacity (an axis listed twice) or
/// non-positive gains.
ConstraintSet BuildConstraintSet(const PlatformParams& platform, const SafetyConfig& safety);

/// The band the leg-stroke barriers keep each leg length in (m): the
/// stroke [leg_min_length_m, leg_max_length_m] drawn in by
/// safety.leg_stroke.margin_m at each end.
struct LegStrokeBand {
  double lower_m = 0.0;
  double upper_m = 0.0;
};
LegStrokeBand LegStrokeBandOf(const PlatformParams& platform, const LegStrokeLimitConfig& stroke);

}  // namespace stewart::safety
