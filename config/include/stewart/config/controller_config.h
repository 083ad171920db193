#pragma once
#include "stewart/config/config_node.h"

namespace stewart {

/// `controller`: feedback-linearising PD gains of paper eq. 3.
struct ControllerConfig {
  Vector6d kp = Vector6d::Zero();  ///< 1/s^2
  Vector6d kd = Vector6d::Zero();  ///< 1/s
};

ControllerConfig ParseControllerConfig(const ConfigNode& controller);

}  // namespace stewart
