#pragma once
// The whole stack's configuration, loaded from one YAML file by one loader.
#include <string>

#include "stewart/config/config_node.h"
#include "stewart/config/controller_config.h"
#include "stewart/config/estimator_config.h"
#include "stewart/config/hw_bridge_config.h"
#include "stewart/config/lcm_config.h"
#include "stewart/config/plant_sim_config.h"
#include "stewart/config/platform_config.h"
#include "stewart/config/safety_config.h"
#include "stewart/config/sensor_config.h"
#include "stewart/model/platform_params.h"

namespace stewart {

struct StackConfig {
  PlatformParams platform;
  Vector6d home_pose = Vector6d::Zero();
  ActuatorConfig actuators;
  SensorConfig sensors;
  ControllerConfig controller;
  SafetyConfig safety;
  EstimatorConfig estimator;
  PlantSimConfig plant_sim;
  HwBridgeConfig hw_bridge;
  LcmConfig lcm;
  std::string source_path;  ///< file it was loaded from, "" for strings
};

/// Loads and validates; throws ConfigError naming the key and the reason.
StackConfig LoadStackConfig(const std::string& path);
StackConfig ParseStackConfig(const std::string& yaml_text);

/// Cross-section checks (home pose inside the stroke and inside every limit,
/// ...). Called by the loaders; exposed for configs built in code.
void ValidateStackConfig(const StackConfig& config);

/// Default config file: $STEWART_CONFIG, else config/platform.yaml of the
/// source tree this binary was built from.
std::string DefaultConfigPath();

}  // namespace stewart
