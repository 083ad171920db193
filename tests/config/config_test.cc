// Every invalid value gives one ConfigError naming the key and the reason.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <limits>

#include "stewart/config/config_loader.h"

namespace stewart {
namespace {

YAML::Node DefaultYaml() { return YAML::LoadFile(DefaultConfigPath()); }

std::string Emit(const YAML::Node& node) {
  YAML::Emitter out;
  out << node;
  return out.c_str();
}

// Expects the mutated config to fail with an error at `key` whose reason
// contains `reason_part`.
void ExpectConfigError(const std::function<void(YAML::Node&)>& mutate, const std::string& key,
                       const std::string& reason_part) {
  YAML::Node yaml = DefaultYaml();
  mutate(yaml);
  try {
    ParseStackConfig(Emit(yaml));
    ADD_FAILURE() << "no error for " << key;
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.key(), key) << e.what();
    EXPECT_NE(e.reason().find(reason_part), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(key), std::string::npos);
  }
}

TEST(Config, DefaultLoadsWithPaperValues) {
  const StackConfig c = LoadStackConfig(DefaultConfigPath());
  EXPECT_DOUBLE_EQ(c.platform.base_joints_in_B_m.col(0).norm(), 0.20);
  EXPECT_DOUBLE_EQ(c.platform.platform_joints_in_P_m.col(0).norm(), 0.16);
  EXPECT_DOUBLE_EQ(c.platform.leg_max_length_m - c.platform.leg_min_length_m, 0.2);
  EXPECT_DOUBLE_EQ(c.home_pose(2), 0.4);
  EXPECT_EQ(c.safety.position_limits.size(), 3u);
  EXPECT_EQ(c.safety.velocity_limits.size(), 3u);
  EXPECT_DOUBLE_EQ(c.safety.velocity_limits[2].alpha_v, 2.0);  // paper: z alpha_v = 2
  EXPECT_EQ(c.lcm.channels.sensors, "STEWART_SENSORS");
  EXPECT_EQ(c.lcm.channels.command_safe, "STEWART_CMD_SAFE");
}

TEST(Config, ChannelSuffix) {
  StackConfig c = LoadStackConfig(DefaultConfigPath());
  SetChannelSuffix(&c.lcm, "_B");
  EXPECT_EQ(c.lcm.channels.state_estimate, "STEWART_STATE_EST_B");
  SetChannelSuffix(&c.lcm, "_C");
  EXPECT_EQ(c.lcm.channels.state_estimate, "STEWART_STATE_EST_C");
  SetChannelSuffix(&c.lcm, "");
  EXPECT_EQ(c.lcm.channels.state_estimate, "STEWART_STATE_EST");
}

TEST(Config, MissingKey) {
  ExpectConfigError([](YAML::Node& y) { y["platform"].remove("mass_kg"); }, "platform.mass_kg",
                    "missing");
  ExpectConfigError([](YAML::Node& y) { y.remove("safety"); }, "safety", "missing");
  ExpectConfigError([](YAML::Node& y) { y["lcm"]["channels"].remove("health"); },
                    "lcm.channels.health", "missing");
}

TEST(Config, WrongType) {
  ExpectConfigError([](YAML::Node& y) { y["safety"]["k_position"] = "large"; }, "safety.k_position",
                    "expected a number");
  ExpectConfigError([](YAML::Node& y) { y["controller"]["kp"] = 3.0; }, "controller.kp",
                    "list of 6");
  ExpectConfigError([](YAML::Node& y) { y["sensors"]["has_orientation"] = "maybe"; },
                    "sensors.has_orientation", "true or false");
  ExpectConfigError([](YAML::Node& y) { y["safety"]["variant"] = "fastest"; }, "safety.variant",
                    "not one of");
  ExpectConfigError([](YAML::Node& y) { y["safety"]["position_limits"][0]["axis"] = "w"; },
                    "safety.position_limits[0].axis", "not one of");
}

TEST(Config, CorrectionMetricAndFrictionModel) {
  const StackConfig c = LoadStackConfig(DefaultConfigPath());
  EXPECT_EQ(c.safety.correction_metric, CorrectionMetric::kAcceleration);
  // One friction coefficient: the actuators'.
  EXPECT_GT(c.actuators.viscous_friction_nspm, 0.0);
  EXPECT_EQ(c.controller.leg_friction_nspm, c.actuators.viscous_friction_nspm);
  EXPECT_EQ(c.safety.leg_friction_nspm, c.actuators.viscous_friction_nspm);
  YAML::Node yaml = DefaultYaml();
  yaml["controller"]["compensate_friction"] = false;
  yaml["safety"]["model_leg_friction"] = false;
  yaml["safety"].remove("correction_metric");  // optional: the paper's force metric
  const StackConfig off = ParseStackConfig(Emit(yaml));
  EXPECT_EQ(off.controller.leg_friction_nspm, 0.0);
  EXPECT_EQ(off.safety.leg_friction_nspm, 0.0);
  EXPECT_EQ(off.safety.correction_metric, CorrectionMetric::kForce);
  ExpectConfigError([](YAML::Node& y) { y["safety"]["correction_metric"] = "energy"; },
                    "safety.correction_metric", "not one of");
  ExpectConfigError([](YAML::Node& y) { y["controller"]["compensate_friction"] = "yes please"; },
                    "controller.compensate_friction", "true or false");
}

TEST(Config, JointToleranceAndAccelerometerBiasAxes) {
  const StackConfig c = LoadStackConfig(DefaultConfigPath());
  EXPECT_DOUBLE_EQ(c.safety.joint_radius_tolerance_m, 0.001);
  EXPECT_DOUBLE_EQ(c.safety.joint_angle_tolerance_rad, 0.5 * M_PI / 180.0);
  EXPECT_EQ(c.safety.home_pose[2], c.home_pose(2));
  EXPECT_FALSE(c.estimator.estimate_accel_bias_z);
  YAML::Node yaml = DefaultYaml();
  yaml["safety"].remove("joint_position_tolerance");  // optional: no margin
  yaml["estimator"].remove("accel_bias_axes");        // optional: every axis
  const StackConfig defaults = ParseStackConfig(Emit(yaml));
  EXPECT_EQ(defaults.safety.joint_radius_tolerance_m, 0.0);
  EXPECT_EQ(defaults.safety.joint_angle_tolerance_rad, 0.0);
  EXPECT_TRUE(defaults.estimator.estimate_accel_bias_z);
  ExpectConfigError(
      [](YAML::Node& y) { y["safety"]["joint_position_tolerance"]["radius_m"] = -0.001; },
      "safety.joint_position_tolerance.radius_m", "negative");
  ExpectConfigError(
      [](YAML::Node& y) { y["safety"]["joint_position_tolerance"].remove("angle_deg"); },
      "safety.joint_position_tolerance.angle_deg", "missing");
  ExpectConfigError([](YAML::Node& y) { y["estimator"]["accel_bias_axes"] = "xz"; },
                    "estimator.accel_bias_axes", "not one of");
}

TEST(Config, DriveOnResponseAndCommandLatencyAllowance) {
  const StackConfig c = LoadStackConfig(DefaultConfigPath());
  EXPECT_DOUBLE_EQ(c.safety.drive_on_response_s, 0.003);
  EXPECT_DOUBLE_EQ(c.estimator.command_latency_allowance_s, 0.002);
  YAML::Node yaml = DefaultYaml();
  yaml["safety"].remove("drive_on_response_s");             // optional: the model's hold
  yaml["estimator"].remove("command_latency_allowance_s");  // optional: none
  const StackConfig defaults = ParseStackConfig(Emit(yaml));
  EXPECT_EQ(defaults.safety.drive_on_response_s, 0.0);
  EXPECT_EQ(defaults.estimator.command_latency_allowance_s, 0.0);
  ExpectConfigError([](YAML::Node& y) { y["safety"]["drive_on_response_s"] = -0.001; },
                    "safety.drive_on_response_s", "negative");
  ExpectConfigError([](YAML::Node& y) { y["estimator"]["command_latency_allowance_s"] = -1.0; },
                    "estimator.command_latency_allowance_s", "negative");
}

TEST(Config, ForceChangeAllowance) {
  const StackConfig c = LoadStackConfig(DefaultConfigPath());
  EXPECT_DOUBLE_EQ(c.estimator.disturbance_force_change_std, 0.1);
  YAML::Node yaml = DefaultYaml();
  yaml["estimator"]["disturbance"].remove("force_change_std");  // optional: none
  EXPECT_EQ(ParseStackConfig(Emit(yaml)).estimator.disturbance_force_change_std, 0.0);
  ExpectConfigError([](YAML::Node& y) { y["estimator"]["disturbance"]["force_change_std"] = -0.1; },
                    "estimator.disturbance.force_change_std", "negative");
  EXPECT_DOUBLE_EQ(c.estimator.disturbance_force_change_cap_n, 2.0);
  yaml["estimator"]["disturbance"].remove("force_change_cap_n");  // optional: no cap
  EXPECT_TRUE(std::isinf(ParseStackConfig(Emit(yaml)).estimator.disturbance_force_change_cap_n));
  ExpectConfigError(
      [](YAML::Node& y) { y["estimator"]["disturbance"]["force_change_cap_n"] = 0.0; },
      "estimator.disturbance.force_change_cap_n", "positive");
}

TEST(Config, AccelUpdateDynamicsStd) {
  // Optional: unset, the accelerometer's update takes the velocity's process
  // noise (dynamics_accel_std_mps2); the P-16P overlay sets it apart.
  EXPECT_LT(LoadStackConfig(DefaultConfigPath()).estimator.accel_update_dynamics_std_mps2, 0.0);
  YAML::Node yaml = DefaultYaml();
  yaml["estimator"]["accel_update_dynamics_std_mps2"] = 0.1;
  EXPECT_DOUBLE_EQ(ParseStackConfig(Emit(yaml)).estimator.accel_update_dynamics_std_mps2, 0.1);
  ExpectConfigError([](YAML::Node& y) { y["estimator"]["accel_update_dynamics_std_mps2"] = 0.0; },
                    "estimator.accel_update_dynamics_std_mps2", "positive");
  ExpectConfigError(
      [](YAML::Node& y) { y["estimator"]["accel_update_dynamics_std_mps2"] = "wide"; },
      "estimator.accel_update_dynamics_std_mps2", "number");
}

TEST(Config, EarlyJump) {
  const StackConfig c = LoadStackConfig(DefaultConfigPath());
  EXPECT_EQ(c.estimator.disturbance_early_jump_calm_samples, 50);  // docs/estimator.md, "Steps"
  YAML::Node yaml = DefaultYaml();
  yaml["estimator"]["disturbance"].remove("early_jump_calm_samples");  // optional: off
  EXPECT_EQ(ParseStackConfig(Emit(yaml)).estimator.disturbance_early_jump_calm_samples, 0);
  ExpectConfigError(
      [](YAML::Node& y) { y["estimator"]["disturbance"]["early_jump_calm_samples"] = -1; },
      "estimator.disturbance.early_jump_calm_samples", "negative");
  ExpectConfigError(
      [](YAML::Node& y) { y["estimator"]["disturbance"]["early_jump_calm_samples"] = 2.5; },
      "estimator.disturbance.early_jump_calm_samples", "integer");
  EXPECT_DOUBLE_EQ(c.estimator.disturbance_early_jump_max_step_n, 6.0);
  yaml["estimator"]["disturbance"].remove("early_jump_max_step_n");  // optional: no limit
  EXPECT_TRUE(std::isinf(ParseStackConfig(Emit(yaml)).estimator.disturbance_early_jump_max_step_n));
  ExpectConfigError(
      [](YAML::Node& y) { y["estimator"]["disturbance"]["early_jump_max_step_n"] = 0.0; },
      "estimator.disturbance.early_jump_max_step_n", "positive");
}

TEST(Config, FrictionFlipAllowance) {
  const StackConfig c = LoadStackConfig(DefaultConfigPath());
  EXPECT_DOUBLE_EQ(c.estimator.disturbance_friction_flip_std_n, 0.1);
  YAML::Node yaml = DefaultYaml();
  yaml["estimator"]["disturbance"].remove("friction_flip_std_n");  // optional: none
  EXPECT_EQ(ParseStackConfig(Emit(yaml)).estimator.disturbance_friction_flip_std_n, 0.0);
  ExpectConfigError(
      [](YAML::Node& y) { y["estimator"]["disturbance"]["friction_flip_std_n"] = -0.1; },
      "estimator.disturbance.friction_flip_std_n", "negative");
}

TEST(Config, GyroBiasWalkPerSpeed) {
  const StackConfig c = LoadStackConfig(DefaultConfigPath());
  EXPECT_DOUBLE_EQ(c.estimator.gyro_bias_walk_per_speed, 1e-3);
  YAML::Node yaml = DefaultYaml();
  yaml["estimator"].remove("gyro_bias_walk_per_speed");  // optional: none
  EXPECT_EQ(ParseStackConfig(Emit(yaml)).estimator.gyro_bias_walk_per_speed, 0.0);
  ExpectConfigError([](YAML::Node& y) { y["estimator"]["gyro_bias_walk_per_speed"] = -1e-3; },
                    "estimator.gyro_bias_walk_per_speed", "negative");
}

TEST(Config, AccelBiasWalkPerSpeed) {
  const StackConfig c = LoadStackConfig(DefaultConfigPath());
  EXPECT_DOUBLE_EQ(c.estimator.accel_bias_walk_per_speed, 0.3);
  YAML::Node yaml = DefaultYaml();
  yaml["estimator"].remove("accel_bias_walk_per_speed");  // optional: none
  EXPECT_EQ(ParseStackConfig(Emit(yaml)).estimator.accel_bias_walk_per_speed, 0.0);
  ExpectConfigError([](YAML::Node& y) { y["estimator"]["accel_bias_walk_per_speed"] = -0.1; },
                    "estimator.accel_bias_walk_per_speed", "negative");
}

TEST(Config, NotANumber) {
  ExpectConfigError([](YAML::Node& y) { y["platform"]["mass_kg"] = ".nan"; }, "platform.mass_kg",
                    "finite");
  ExpectConfigError([](YAML::Node& y) { y["controller"]["kd"][3] = ".inf"; }, "controller.kd[3]",
                    "finite");
}

TEST(Config, NegativeMassAndInertia) {
  ExpectConfigError([](YAML::Node& y) { y["platform"]["mass_kg"] = -1.0; }, "platform.mass_kg",
                    "positive");
  ExpectConfigError([](YAML::Node& y) { y["legs"]["rod_mass_kg"] = -0.1; }, "legs.rod_mass_kg",
                    "negative");
  ExpectConfigError([](YAML::Node& y) { y["platform"]["inertia_kgm2"][2] = 1.0; },
                    "platform.inertia_kgm2", "triangle");
}

TEST(Config, LimitsExcludingHomePose) {
  ExpectConfigError([](YAML::Node& y) { y["safety"]["position_limits"][2]["upper"] = 0.39; },
                    "safety.position_limits[2].upper", "home pose");
  ExpectConfigError(
      [](YAML::Node& y) {
        y["safety"]["position_limits"][0].remove("upper");
        y["safety"]["position_limits"][0]["lower"] = 0.05;
      },
      "safety.position_limits[0].lower", "home pose");
  ExpectConfigError([](YAML::Node& y) { y["safety"]["velocity_limits"][0]["upper"] = -0.01; },
                    "safety.velocity_limits[0].upper", "standing still");
  ExpectConfigError(
      [](YAML::Node& y) {
        y["safety"]["leg_stroke"]["enabled"] = true;
        y["safety"]["leg_stroke"]["margin_m"] = 0.05;
      },
      "safety.leg_stroke.margin_m", "home pose");
}

TEST(Config, HomePoseOutsideStroke) {
  ExpectConfigError([](YAML::Node& y) { y["platform"]["home_pose"][2] = 0.7; },
                    "platform.home_pose", "outside the actuator stroke");
  ExpectConfigError([](YAML::Node& y) { y["actuators"]["stroke_m"] = 0.02; }, "platform.home_pose",
                    "outside the actuator stroke");
}

TEST(Config, InvalidYamlAndMissingFile) {
  EXPECT_THROW(ParseStackConfig("platform: [unclosed"), ConfigError);
  EXPECT_THROW(LoadStackConfig("/nonexistent/platform.yaml"), ConfigError);
}

// A process given a bad config exits non-zero with one line naming the key.
TEST(Config, ToolExitsNonZeroNamingTheKey) {
  YAML::Node yaml = DefaultYaml();
  yaml["platform"]["mass_kg"] = -2.0;
  const std::string path = ::testing::TempDir() + "bad_config.yaml";
  std::ofstream(path) << Emit(yaml);
  const std::string cmd = std::string(MODEL_TOOL_PATH) + " --config " + path + " 2>&1";
  FILE* pipe = popen(cmd.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::string output;
  std::array<char, 256> buffer{};
  while (fgets(buffer.data(), buffer.size(), pipe) != nullptr) output += buffer.data();
  const int status = pclose(pipe);
  EXPECT_NE(status, 0);
  EXPECT_NE(output.find("platform.mass_kg"), std::string::npos) << output;
  EXPECT_NE(output.find("positive"), std::string::npos) << output;
}

}  // namespace
}  // namespace stewart
