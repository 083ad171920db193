#pragma once
#include "stewart/model/types.h"

namespace stewart {

/// `controller`: feedback-linearising PD gains of paper eq. 3.
struct ControllerConfig {
  Vector6d kp = Vector6d::Zero();  ///< 1/s^2
  Vector6d kd = Vector6d::Zero();  ///< 1/s
  /// Optional key `compensate_friction` (default true): F_des also cancels
  /// the legs' viscous friction, leg_friction_nspm = actuators.viscous_friction_nspm
  /// (set by ParseStackConfig), else 0.
  bool compensate_friction = true;
  /// Optional key `compensate_disturbance` (default true): F_des also cancels
  /// the state's estimate of the model error d (docs/controller.md).
  bool compensate_disturbance = true;
  double leg_friction_nspm = 0.0;  ///< N per m/s of leg speed
  /// Optional key `stale_age_s` (default 0.02 s, safety.stale_age_s's
  /// default): rejecting every state estimate for longer than this is a
  /// FAULT (common/input_starvation.h).
  double stale_age_s = 0.02;
};

}  // namespace stewart
