#include "plant_test_util.h"

namespace stewart::test {

const StackConfig& Config() { return DefaultStackConfig(); }

PlantModel DefaultModel() { return PlantModel{Config().platform, Config().actuators}; }

OdeOptions OdeOptionsFor(const std::string& integrator) {
  PlantSimConfig plant_sim = Config().plant_sim;
  plant_sim.integrator = integrator;
  return OdeOptionsFrom(plant_sim);
}

PlantStateVector Rk4Step(const PlantModel& model, const PlantInputs& u, const PlantStateVector& x,
                         double h) {
  PlantRates r;
  PlantDerivative(model, u, x, &r);
  const PlantStateVector k1 = r.x_dot;
  PlantDerivative(model, u, x + h / 2 * k1, &r);
  const PlantStateVector k2 = r.x_dot;
  PlantDerivative(model, u, x + h / 2 * k2, &r);
  const PlantStateVector k3 = r.x_dot;
  PlantDerivative(model, u, x + h * k3, &r);
  const PlantStateVector k4 = r.x_dot;
  return x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
}

Vector6d HoldingForce(const PlatformParams& platform, const Vector6d& q) {
  return InverseDynamics(EvaluateDynamics(platform, q, Vector6d::Zero()), Vector6d::Zero());
}

}  // namespace stewart::test
