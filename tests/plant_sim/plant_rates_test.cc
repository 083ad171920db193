// Plant::EvaluateRates reuses the integrator's last right-hand side and the
// model terms across a force change: the values must be exactly those of a
// fresh PlantDerivative, with and without force lag (12 or 18 integrated
// states).
#include <gtest/gtest.h>

#include <cmath>

#include "plant_test_util.h"
#include "stewart/plant_sim/actuator_model.h"

namespace stewart {
namespace {

using test::Config;

void ExpectSameRates(const PlantRates& a, const PlantRates& b) {
  EXPECT_EQ(a.x_dot, b.x_dot);
  EXPECT_EQ(a.leg_force_n, b.leg_force_n);
  EXPECT_EQ(a.terms.M, b.terms.M);
  EXPECT_EQ(a.terms.C_qd, b.terms.C_qd);
  EXPECT_EQ(a.terms.G, b.terms.G);
  EXPECT_EQ(a.terms.H, b.terms.H);
  EXPECT_EQ(a.terms.leg_length_m, b.terms.leg_length_m);
}

class PlantRatesCache : public ::testing::TestWithParam<double> {};

TEST_P(PlantRatesCache, EqualsFreshEvaluation) {
  PlantModel model = test::DefaultModel();
  model.actuators.force_lag_s = GetParam();
  Plant plant(model, test::OdeOptionsFor("arkode_erk"));
  const Vector6d q0 = Config().plant_sim.initial_pose;
  plant.Reset(0.0, q0, Vector6d::Zero());
  const Vector6d hold = test::HoldingForce(model.platform, q0);
  PlantRates fresh;
  for (int k = 0; k < 200; ++k) {
    Vector6d f = hold;
    for (int i = 0; i < kNumLegs; ++i) f(i) += 2.0 * std::sin(5.0 * k * 1e-3 + i);
    plant.SetForceCommand(f);
    // Right after a force change: new inputs, same state.
    PlantDerivative(model, plant.inputs(), plant.state(), &fresh);
    ExpectSameRates(plant.EvaluateRates(), fresh);
    plant.Advance(1e-3);
    // Right after a tick: the integrator's last evaluation.
    PlantDerivative(model, plant.inputs(), plant.state(), &fresh);
    ExpectSameRates(plant.EvaluateRates(), fresh);
    if (k == 100) plant.SetActuatorsOff(true);
  }
  EXPECT_TRUE(plant.actuators_off());
  // Without lag the state still carries the motor force: sat(F_cmd).
  if (!(GetParam() > 0.0)) {
    EXPECT_EQ(MotorForceOf(plant.state()),
              SaturateForce(model.actuators, plant.inputs().force_cmd_n));
  }
}

INSTANTIATE_TEST_SUITE_P(ForceLag, PlantRatesCache, ::testing::Values(0.0, 0.01));

}  // namespace
}  // namespace stewart
