#pragma once
#include "stewart/config/config_node.h"

namespace stewart {

/// `estimator`: EKF tuning.
struct EstimatorConfig {
  double process_accel_std_mps2 = 0.5;
  double process_angaccel_std_radps2 = 2.0;
  double gating_chi2 = 30.0;
  bool perfect_state = false;  ///< pass ground truth through; testing only
};

EstimatorConfig ParseEstimatorConfig(const ConfigNode& estimator);

}  // namespace stewart
