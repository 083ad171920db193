// Actuator identification in process (docs/hardware.md, "Identify the
// actuators"): the procedure against plant_sim's Plant with DC-motor legs
// whose parameters differ from the config's, the fit, the overlay.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "stewart/config/default_config.h"
#include "stewart/identify/actuator_fit.h"
#include "stewart/identify/actuator_overlay.h"
#include "stewart/identify/actuator_procedure.h"
#include "stewart/identify/emulator_device.h"
#include "stewart/identify/plant_device.h"
#include "stewart/model/dc_motor.h"

namespace stewart::identify {
namespace {

const StackConfig& Config() { return DcMotorStackConfig(); }

// The config's plant at home with other motors: each parameter +20 % or -25 %.
PlantTruth OtherMotors() {
  PlantTruth truth = TruthOfConfig(Config());
  truth.initial_pose = Config().home_pose;
  DcMotorParams& m = truth.actuators.motor;
  m.stall_force_n *= 1.2;
  m.no_load_speed_mps *= 0.75;
  m.reflected_mass_kg *= 1.2;
  m.dead_band_duty *= 1.2;
  m.coulomb_friction_n *= 0.75;
  truth.platform.leg.actuator_reflected_mass_kg = m.reflected_mass_kg;
  return truth;
}

ActuatorProcedureOptions ProcedureOptions(const StackConfig& c) {
  ActuatorProcedureOptions o;
  o.guard.min_length_m = c.platform.leg_min_length_m;
  o.guard.max_length_m = c.platform.leg_max_length_m;
  o.guard.margin_m = c.safety.leg_stroke.margin_m;
  o.guard.speed_cap_mps = 0.05;
  return o;
}

void Identify(ActuatorDevice& device, const PlantTruth& truth) {
  const StackConfig& c = Config();
  const ActuatorRecord record =
      RunActuatorProcedure(&device, ProcedureOptions(c),
                           [](const std::string& line) { std::printf("%s\n", line.c_str()); });
  ActuatorFitOptions fo;
  fo.coulomb_friction_n = c.actuators.motor.coulomb_friction_n;
  fo.coulomb_friction_sigma_n = c.actuators.motor.coulomb_friction_n;
  const ActuatorFit fit = FitActuators(c.platform, c.actuators, record, fo);
  std::printf("%s\n", FormatActuatorOverlay(fit, c.actuators, fo, "test").c_str());
  const DcMotorParams& m = truth.actuators.motor;
  MotorVector expected;
  expected(kDeadBandDuty) = m.dead_band_duty;
  expected(kStallForceN) = m.stall_force_n;
  expected(kNoLoadSpeedMps) = m.no_load_speed_mps;
  expected(kReflectedMassKg) = m.reflected_mass_kg;
  expected(kForceAtFullDutyN) = DcMotorForceAtFullDuty(m);
  expected(kLegDampingNspm) = DcMotorBackEmfDampingNspm(m) + truth.actuators.viscous_friction_nspm;
  expected(kStartDuty) =
      m.dead_band_duty + (1 - m.dead_band_duty) * m.coulomb_friction_n / DcMotorForceAtFullDuty(m);
  for (int v = 0; v < kNumMotorValues; ++v) {
    std::printf("%-22s %12.6g +- %9.3g (fit %9.3g)  true %12.6g  error %+7.3f %%  (%+.2f sigma)\n",
                kMotorValueNames[v], fit.values(v), fit.sigma(v), fit.sigma_fit(v), expected(v),
                100 * (fit.values(v) / expected(v) - 1),
                (fit.values(v) - expected(v)) / fit.sigma(v));
    for (const LegFit& leg : fit.legs) {
      std::printf("    leg %d %12.6g +- %9.3g  (%+.2f sigma)\n", leg.leg, leg.values(v),
                  leg.sigma_fit(v), (leg.values(v) - expected(v)) / leg.sigma_fit(v));
    }
  }
  for (const LegFit& leg : fit.legs) {
    std::printf(
        "leg %d: %ld samples, %d excursions, %d iterations, rms %.1f um, inflation %.2f, load %.3f "
        "N\n",
        leg.leg, leg.samples, leg.excursions, leg.iterations, 1e6 * leg.residual_rms_m,
        leg.correlation_inflation, leg.mean_load_n);
  }
}

TEST(ActuatorIdentification, RecoversOtherMotorsInSimulation) {
  const PlantTruth truth = OtherMotors();
  PlantDevice device(Config(), truth);
  Identify(device, truth);
}

TEST(ActuatorIdentification, RecoversOtherMotorsThroughTheEmulator) {
  const StackConfig& c = Config();
  const PlantTruth truth = OtherMotors();
  hw::BringupOptions bringup;
  bringup.enabled = true;
  bringup.guard = hw::DefaultBringupGuard(c.platform.leg_min_length_m, c.platform.leg_max_length_m,
                                          c.safety.leg_stroke.margin_m, c.actuators.motor);
  EmulatorDevice device(c, truth, bringup);
  Identify(device, truth);
}

}  // namespace
}  // namespace stewart::identify
