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
};

}  // namespace stewart
