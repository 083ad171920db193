#include "stewart/config/estimator_config.h"

namespace stewart {

EstimatorConfig ParseEstimatorConfig(const ConfigNode& estimator) {
  EstimatorConfig e;
  e.process_accel_std_mps2 = estimator.PositiveDouble("process_accel_std_mps2");
  e.process_angaccel_std_radps2 = estimator.PositiveDouble("process_angaccel_std_radps2");
  e.gating_chi2 = estimator.PositiveDouble("gating_chi2");
  e.perfect_state = estimator.Bool("perfect_state");
  return e;
}

}  // namespace stewart
