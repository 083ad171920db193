#include "plant_test_util.h"

namespace stewart::test {

const StackConfig& Config() { return DefaultStackConfig(); }

PlantModel DefaultModel() { return PlantModel{Config().platform, Config().actuators}; }

OdeOptions OdeOptionsFor(const std::string& integrator) {
  PlantSimConfig plant_sim = Config().plant_sim;
  plant_sim.integrator = integrator;
  return OdeOptionsFrom(plant_sim);
}

Vector6d HoldingForce(const PlatformParams& platform, const Vector6d& q) {
  return InverseDynamics(EvaluateDynamics(platform, q, Vector6d::Zero()), Vector6d::Zero());
}

}  // namespace stewart::test
