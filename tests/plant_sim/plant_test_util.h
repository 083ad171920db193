#pragma once
// Shared set-up of the plant_sim tests.
#include <string>

#include "stewart/config/default_config.h"
#include "stewart/plant_sim/plant.h"

namespace stewart::test {

const StackConfig& Config();
PlantModel DefaultModel();
OdeOptions OdeOptionsFor(const std::string& integrator);
/// One classic RK4 step of the plant's right-hand side with the inputs held:
/// the independent reference the SUNDIALS integration is checked against.
PlantStateVector Rk4Step(const PlantModel& model, const PlantInputs& u, const PlantStateVector& x,
                         double h);
/// Leg forces that hold the platform at rest at pose q (N).
Vector6d HoldingForce(const PlatformParams& platform, const Vector6d& q);

}  // namespace stewart::test
