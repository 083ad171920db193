#pragma once
// The filter's constraints, built once from the config (docs/safety.md).
//
// Position constraints h(q) >= 0 (m or rad, or m of leg length):
//   axis j:  h = sign (q_j - limit),   dh/dq = sign e_j^T
//   leg i:   h = sign (l_i - limit),   dh/dq = sign J_l(i,:)   (limit = l_max - margin
//                                                               or l_min + margin)
// with sign = -1 for an upper and +1 for a lower limit. Velocity constraints
// h_v(qd) = sign (qd_j - limit) >= 0 (m/s or rad/s).
#include <array>
#include <string>

#include "stewart/model/platform_params.h"
#include "stewart/model/types.h"
#include "stewart/safety/safety_config.h"

namespace stewart::safety {

/// Capacity: a lower and an upper limit per axis, and per leg.
constexpr int kMaxPositionBarriers = 2 * kNumAxes + 2 * kNumLegs;
constexpr int kMaxVelocityBarriers = 2 * kNumAxes;

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

struct VelocityBarrierSpec {
  int axis = 0;
  double sign = -1.0;
  double limit = 0.0;    ///< m/s or rad/s
  double alpha_v = 1.0;  ///< class-K gain (1/s)
  std::string name;      ///< e.g. "zd_upper"
};

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
};

/// Throws InputError (a std::invalid_argument naming the config key) when the
/// config holds more constraints than the capacity (an axis listed twice) or
/// non-positive gains.
ConstraintSet BuildConstraintSet(const PlatformParams& platform, const SafetyConfig& safety);

}  // namespace stewart::safety
