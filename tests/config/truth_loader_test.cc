// Truth files (docs/simulation.md, "Truth"): what they override, what only a
// truth has, and one clear error naming the key for every bad entry.
#include "stewart/config/truth_loader.h"

#include <gtest/gtest.h>

#include <string>

#include "stewart/config/config_loader.h"
#include "stewart/config/default_config.h"
#include "stewart/model/dynamics.h"

namespace stewart {
namespace {

const StackConfig& Config() {
  static const StackConfig config = LoadStackConfig(DefaultConfigPath());
  return config;
}

PlantTruth Parse(const std::string& truth_yaml) {
  return ParsePlantTruth(Config(), LoadYamlFile(DefaultConfigPath()), YAML::Load(truth_yaml));
}

TEST(TruthLoader, EmptyTruthIsTheConfig) {
  const PlantTruth t = Parse("{}");
  EXPECT_EQ(t.platform.platform_mass_kg, Config().platform.platform_mass_kg);
  EXPECT_EQ(t.platform.base_joints_in_B_m, Config().platform.base_joints_in_B_m);
  EXPECT_EQ(t.actuators.viscous_friction_nspm, Config().actuators.viscous_friction_nspm);
  EXPECT_EQ(t.actuator_errors.force_gain, Vector6d::Ones());
  EXPECT_EQ(t.latency.total_s(), 0.0);
  EXPECT_EQ(t.initial_pose, Config().plant_sim.initial_pose);
}

// The shipped corner truths (config/truths/) load and are the corners.
TEST(TruthLoader, TheBoundsCornersLoad) {
  const std::string dir = std::string(STEWART_SOURCE_DIR) + "/config/truths/";
  const PlantTruth heavy = LoadPlantTruth(Config(), dir + "bounds-heavy-corner.yaml");
  const PlantTruth light = LoadPlantTruth(Config(), dir + "bounds-light-corner.yaml");
  EXPECT_GT(heavy.platform.platform_mass_kg, 1.4 * Config().platform.platform_mass_kg);
  EXPECT_LT(light.platform.platform_mass_kg, 0.85 * Config().platform.platform_mass_kg);
  EXPECT_NEAR(heavy.latency.total_s(), 0.002, 1e-12);
  EXPECT_NEAR(light.latency.total_s(), 0.002, 1e-12);

  // The P-16P corners name their legs: over the base config (a truth
  // overrides the file, not an overlay) the plant's legs are DC motors,
  // with the motors at the +-5 % corners.
  const PlantTruth p16p_heavy = LoadPlantTruth(Config(), dir + "bounds-p16p-heavy-corner.yaml");
  const PlantTruth p16p_light = LoadPlantTruth(Config(), dir + "bounds-p16p-light-corner.yaml");
  EXPECT_EQ(p16p_heavy.actuators.kind, ActuatorKind::kDcMotor);
  EXPECT_EQ(p16p_light.actuators.kind, ActuatorKind::kDcMotor);
  EXPECT_EQ(p16p_heavy.platform.platform_mass_kg, heavy.platform.platform_mass_kg);
  EXPECT_EQ(p16p_light.platform.platform_mass_kg, light.platform.platform_mass_kg);
  const DcMotorParams& nominal = Config().actuators.motor;
  EXPECT_NEAR(p16p_heavy.actuators.motor.stall_force_n / nominal.stall_force_n, 0.95, 1e-12);
  EXPECT_NEAR(p16p_light.actuators.motor.stall_force_n / nominal.stall_force_n, 1.05, 1e-12);
}

// A truth that does not name the legs, given with an overlay that does: the
// plant gets the config file's legs, and the loader says what to set.
TEST(TruthLoader, SaysWhenThePlantsLegsAreNotTheStacks) {
  const std::string dir = std::string(STEWART_SOURCE_DIR) + "/config/truths/";
  const StackConfig p16p = LoadStackConfig(DefaultConfigPath(), {DcMotorOverlayPath()});
  const PlantTruth ideal_legs = LoadPlantTruth(p16p, dir + "bounds-heavy-corner.yaml");
  EXPECT_EQ(ideal_legs.actuators.kind, ActuatorKind::kIdealForce);
  const std::string message = TruthLegModelMismatch(p16p, ideal_legs);
  EXPECT_NE(message.find("actuators.model: dc_motor"), std::string::npos) << message;
  EXPECT_EQ(
      TruthLegModelMismatch(p16p, LoadPlantTruth(p16p, dir + "bounds-p16p-heavy-corner.yaml")), "");
  EXPECT_EQ(
      TruthLegModelMismatch(Config(), LoadPlantTruth(Config(), dir + "bounds-heavy-corner.yaml")),
      "");
  EXPECT_EQ(TruthLegModelMismatch(p16p, LoadPlantTruth(p16p, "")), "");
}

TEST(TruthLoader, OverridesKeyByKeyAndKeepsTheRest) {
  const PlantTruth t = Parse(R"(
platform: {mass_kg: 0.9}
legs: {rod_mass_kg: 0.05}
actuators: {viscous_friction_nspm: 4.0, force_gain: 1.1, coulomb_friction_n: [0.1, 0.2, 0.3, 0, 0, 0]}
sensors: {leg_pot_noise_std_m: 1.0e-4, leg_scale: 1.01, imu_misalignment_deg: [0.5, 0, 0]}
latency: {sensor_ms: 0.5, command_ms: 1.5}
initial_state: {pose: [0.01, 0, 0.41, 0, 0, 0]}
)");
  EXPECT_EQ(t.platform.platform_mass_kg, 0.9);
  EXPECT_EQ(t.platform.platform_com_in_P_m, Config().platform.platform_com_in_P_m);
  EXPECT_EQ(t.platform.leg.rod_mass_kg, 0.05);
  EXPECT_EQ(t.platform.leg.cylinder_mass_kg, Config().platform.leg.cylinder_mass_kg);
  EXPECT_EQ(t.actuators.viscous_friction_nspm, 4.0);
  EXPECT_EQ(t.actuators.force_limit_n, Config().actuators.force_limit_n);
  EXPECT_EQ(t.actuator_errors.force_gain, Vector6d::Constant(1.1));
  EXPECT_EQ(t.actuator_errors.coulomb_friction_n(2), 0.3);
  EXPECT_EQ(t.sensors.leg_pot_noise_std_m, 1.0e-4);
  EXPECT_EQ(t.sensor_errors.leg_scale, Vector6d::Constant(1.01));
  EXPECT_NEAR(t.sensor_errors.imu_misalignment_rad(0), 0.5 * 3.141592653589793 / 180.0, 1e-15);
  EXPECT_DOUBLE_EQ(t.latency.total_s(), 2e-3);
  EXPECT_EQ(t.initial_pose(0), 0.01);
  // The sensors' rate and seed are how the simulation runs: the config's.
  EXPECT_EQ(t.sensors.rate_hz, Config().sensors.rate_hz);
}

TEST(TruthLoader, WholeConfigFileIsATruth) {
  const PlantTruth t = ParsePlantTruth(Config(), LoadYamlFile(DefaultConfigPath()),
                                       LoadYamlFile(DefaultConfigPath()));
  EXPECT_EQ(t.platform.platform_mass_kg, Config().platform.platform_mass_kg);
  EXPECT_EQ(t.platform.platform_inertia_kgm2, Config().platform.platform_inertia_kgm2);
}

TEST(TruthLoader, PerJointRadiusOffsetsMoveOnlyThatJoint) {
  const PlantTruth t = Parse("platform: {base_joint_radius_offsets_m: [0.001, 0, 0, 0, 0, 0]}");
  const auto& b0 = Config().platform.base_joints_in_B_m;
  EXPECT_NEAR(t.platform.base_joints_in_B_m.col(0).head<2>().norm(),
              b0.col(0).head<2>().norm() + 0.001, 1e-15);
  EXPECT_EQ(t.platform.base_joints_in_B_m.col(1), b0.col(1));
}

// A point payload on the z axis of {P}: the mass adds, the CoM moves by the
// lever rule, and the tensor gains exactly the parallel-axis terms.
TEST(TruthLoader, PayloadCombinesByTheParallelAxisTheorem) {
  const PlantTruth t = Parse("platform: {payload: {mass_kg: 0.3, position_m: [0.05, 0, 0.02]}}");
  const PlatformParams& p0 = Config().platform;
  const double m0 = p0.platform_mass_kg, m = m0 + 0.3;
  EXPECT_DOUBLE_EQ(t.platform.platform_mass_kg, m);
  const Vector3d payload(0.05, 0, 0.02);
  const Vector3d com = (m0 * p0.platform_com_in_P_m + 0.3 * payload) / m;
  EXPECT_TRUE(t.platform.platform_com_in_P_m.isApprox(com, 1e-14));
  // About the new CoM: I0 + m0 (|d0|^2 1 - d0 d0^T) + m_l (|d_l|^2 1 - d_l d_l^T).
  const Vector3d d0 = p0.platform_com_in_P_m - com, dl = payload - com;
  const Matrix3d expected = PlatformInertiaInP(p0) +
                            m0 * (d0.squaredNorm() * Matrix3d::Identity() - d0 * d0.transpose()) +
                            0.3 * (dl.squaredNorm() * Matrix3d::Identity() - dl * dl.transpose());
  EXPECT_TRUE(PlatformInertiaInP(t.platform).isApprox(expected, 1e-12));
  EXPECT_NE(t.platform.platform_inertia_products_kgm2(1), 0.0);  // Ixz from the x, z offset
  // And the dynamics see it: more weight to hold.
  const Vector6d q = Config().home_pose;
  const Vector6d g0 = EvaluateDynamics(p0, q, Vector6d::Zero()).G;
  const Vector6d g1 = EvaluateDynamics(t.platform, q, Vector6d::Zero()).G;
  EXPECT_NEAR(g1(2) - g0(2), 0.3 * p0.gravity_mps2, 1e-9);
}

struct BadTruth {
  const char* yaml;
  const char* key;  // the key the error must name
};

class TruthLoaderRejects : public ::testing::TestWithParam<BadTruth> {};

TEST_P(TruthLoaderRejects, NamingTheKey) {
  try {
    Parse(GetParam().yaml);
    FAIL() << "accepted: " << GetParam().yaml;
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find(GetParam().key), std::string::npos) << e.what();
  }
}

INSTANTIATE_TEST_SUITE_P(
    Cases, TruthLoaderRejects,
    ::testing::Values(
        BadTruth{"platfrom: {mass_kg: 1}", "truth.platfrom"},
        BadTruth{"platform: {mass: 1}", "truth.platform.mass"},
        BadTruth{"platform: {mass_kg: -1}", "truth.platform.mass_kg"},
        BadTruth{"platform: {payload: {mass_kg: -0.1}}", "truth.platform.payload.mass_kg"},
        BadTruth{"platform: {payload: {mas_kg: 0.1}}", "truth.platform.payload.mas_kg"},
        BadTruth{"platform: {base_joint_radius_offsets_m: [1, 2]}",
                 "truth.platform.base_joint_radius_offsets_m"},
        BadTruth{"actuators: {force_gain: 0}", "truth.actuators.force_gain"},
        BadTruth{"actuators: {coulomb_friction_n: -0.1}", "truth.actuators.coulomb_friction_n"},
        BadTruth{"sensors: {leg_scale: abc}", "truth.sensors.leg_scale"},
        BadTruth{"latency: {command_ms: 900}", "truth.latency.command_ms"},
        BadTruth{"latency: {sensor_ms: -1}", "truth.latency.sensor_ms"},
        BadTruth{"initial_state: {pose: [0, 0, 0.9, 0, 0, 0]}", "truth.initial_state.pose"},
        BadTruth{"disturbance: {pulses: [{start_s: 1, duration_s: 0}]}",
                 "truth.disturbance.pulses[0].duration_s"},
        BadTruth{"disturbance: {random_pushes: {rate_hz: 1}}",
                 "truth.disturbance.random_pushes.max_force_n"},
        BadTruth{"disturbance: {wind: 1}", "truth.disturbance.wind"}));

}  // namespace
}  // namespace stewart
