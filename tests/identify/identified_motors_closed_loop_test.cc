// The bring-up identification closes the loop on motors that are not the
// config's: for plants whose P-16P motors differ from actuators.motor by up
// to 30 % in every parameter, the stack with the identified overlay holds
// every limit of the paper scenario within 1 mm and 1 mm/s on ground truth
// (in process: the identification against plant_sim's Plant, then the
// closed loop against the same plant).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <ostream>
#include <string>

#include "stewart/config/config_loader.h"
#include "stewart/config/default_config.h"
#include "stewart/config/scenario_loader.h"
#include "stewart/identify/simulated_identification.h"
#include "stewart/stack/closed_loop.h"

namespace stewart::identify {
namespace {

constexpr double kToleranceM = 1e-3;  // docs/safety.md: 1 mm and 1 mm/s

struct MotorScales {
  const char* name;
  double stall_force, no_load_speed, reflected_mass, dead_band, coulomb_friction, back_drive;
};

// Each parameter at an end of +-30 %: the direction that overshoots (a
// faster, lighter motor with less damping than the model) and its opposite,
// and a mix.
const MotorScales kPlants[] = {
    {"faster_lighter", 0.7, 1.3, 0.7, 1.3, 0.7, 0.7},
    {"slower_heavier", 1.3, 0.7, 1.3, 0.7, 1.3, 1.3},
    {"mixed", 1.3, 1.3, 0.7, 0.7, 1.3, 0.7},
};

PlantTruth TruthOf(const StackConfig& config, const MotorScales& s) {
  PlantTruth truth = TruthOfConfig(config);
  truth.initial_pose = config.home_pose;
  DcMotorParams& m = truth.actuators.motor;
  m.stall_force_n *= s.stall_force;
  m.no_load_speed_mps *= s.no_load_speed;
  m.reflected_mass_kg *= s.reflected_mass;
  m.dead_band_duty *= s.dead_band;
  m.coulomb_friction_n *= s.coulomb_friction;
  m.back_drive_force_n *= s.back_drive;
  truth.platform.leg.actuator_reflected_mass_kg = m.reflected_mass_kg;
  return truth;
}

void PrintTo(const MotorScales& s, std::ostream* os) { *os << s.name; }

// The paper scenario against `truth` with the stack's `config`.
ClosedLoopSummary RunPaper(const StackConfig& config, const PlantTruth& truth) {
  ClosedLoopOptions options;
  options.truth = truth;
  const ClosedLoopSummary s =
      RunClosedLoop(config, LoadScenario(ResolveScenarioPath("paper")), options, nullptr);
  EXPECT_TRUE(s.failure.empty()) << s.failure;
  std::printf("  %s, worst excess %.3g (%s), %ld estimator restarts\n",
              s.completed ? "completed" : "stopped", s.max_limit_excess,
              s.max_limit_excess_name.c_str(), s.estimator_reinits);
  return s;
}

class IdentifiedMotors : public ::testing::TestWithParam<MotorScales> {};

TEST_P(IdentifiedMotors, PaperScenarioHoldsTheLimitsAfterTheIdentification) {
  const StackConfig& config = DcMotorStackConfig();
  const PlantTruth truth = TruthOf(config, GetParam());

  // Identify, as stewart_identify --mode actuators --plant sim does.
  const std::string overlay_path = ::testing::TempDir() + "identified_motors_" +
                                   std::to_string(::getpid()) + "_" + GetParam().name + ".yaml";
  std::ofstream(overlay_path) << IdentifyActuatorsInSimulation(
      config, truth, "identified_motors_closed_loop_test");
  const StackConfig identified =
      LoadStackConfig(DefaultConfigPath(), {DcMotorOverlayPath(), overlay_path});
  std::remove(overlay_path.c_str());

  // The config's motors, for comparison (docs/campaign.md, "The P-16P legs").
  std::printf("%s, the config's motors:\n", GetParam().name);
  RunPaper(config, truth);
  std::printf("%s, the identified motors:\n", GetParam().name);
  const ClosedLoopSummary after = RunPaper(identified, truth);
  EXPECT_TRUE(after.completed);
  EXPECT_LT(after.max_limit_excess, kToleranceM) << after.max_limit_excess_name;
  EXPECT_EQ(after.estimator_reinits, 0);
}

INSTANTIATE_TEST_SUITE_P(PlusMinus30Percent, IdentifiedMotors, ::testing::ValuesIn(kPlants),
                         [](const ::testing::TestParamInfo<MotorScales>& p) {
                           return std::string(p.param.name);
                         });

}  // namespace
}  // namespace stewart::identify
