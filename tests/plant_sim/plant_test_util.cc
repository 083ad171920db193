#include "plant_test_util.h"

namespace stewart::test {

const StackConfig& Config() {
  static const StackConfig config = LoadStackConfig(DefaultConfigPath());
  return config;
}

PlantModel DefaultModel() { return PlantModel{Config().platform, Config().actuators}; }

OdeOptions OdeOptionsFor(const std::string& integrator) {
  OdeOptions o;
  o.method = ParseOdeMethod(integrator);
  o.rel_tol = Config().plant_sim.rel_tol;
  o.abs_tol = Config().plant_sim.abs_tol;
  return o;
}

Vector6d HoldingForce(const PlatformParams& platform, const Vector6d& q) {
  return InverseDynamics(EvaluateDynamics(platform, q, Vector6d::Zero()), Vector6d::Zero());
}

}  // namespace stewart::test
