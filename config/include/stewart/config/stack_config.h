#pragma once
// The whole stack's configuration: every library's parameter struct in one
// place. The struct only (no YAML): stewart/config/config_loader.h loads it.
#include <string>

#include "stewart/controller/controller_config.h"
#include "stewart/estimator/estimator_config.h"
#include "stewart/guard/guard_config.h"
#include "stewart/hw_bridge/hw_bridge_config.h"
#include "stewart/model/actuator_params.h"
#include "stewart/model/dc_motor.h"
#include "stewart/model/platform_params.h"
#include "stewart/model/sensor_params.h"
#include "stewart/node/lcm_config.h"
#include "stewart/plant_sim/plant_dynamics.h"
#include "stewart/plant_sim/plant_sim_config.h"
#include "stewart/plant_sim/truth.h"
#include "stewart/safety/safety_config.h"
#include "stewart/safety/supervisor.h"

namespace stewart {

struct StackConfig {
  PlatformParams platform;
  Vector6d home_pose = Vector6d::Zero();
  ActuatorConfig actuators;
  SensorConfig sensors;
  ControllerConfig controller;
  SafetyConfig safety;
  safety::SupervisorConfig supervisor;
  EstimatorConfig estimator;
  PlantSimConfig plant_sim;
  HwBridgeConfig hw_bridge;
  GuardConfig guard;
  LcmConfig lcm;
  std::string source_path;  ///< file it was loaded from, "" for strings
};

/// The plant equal to the model: the config's own physics and initial state,
/// no errors (what a plant runs without a truth file).
inline PlantTruth TruthOfConfig(const StackConfig& config) {
  PlantTruth t;
  t.platform = config.platform;
  t.actuators = config.actuators;
  t.sensors = config.sensors;
  t.initial_pose = config.plant_sim.initial_pose;
  t.initial_velocity = config.plant_sim.initial_velocity;
  return t;
}

/// The stack's force -> duty map (the H-bridge driver): hw_bridge applies it
/// to the device; plant_sim, standing in for hw_bridge, applies it to a
/// DC-motor plant (PlantModel::duty_map).
inline ForceToDutyMap DriverMapOf(const StackConfig& config) {
  ForceToDutyMap map;
  map.force_limit_n = config.actuators.force_limit_n;
  map.force_at_full_duty_n = config.hw_bridge.force_at_full_duty_n;
  map.dead_band_duty = config.hw_bridge.duty_deadband;
  map.max_duty = config.hw_bridge.max_duty;
  return map;
}

/// The simulated plant of a truth, driven as the stack drives it.
inline PlantModel PlantModelOf(const PlantTruth& truth, const StackConfig& config) {
  PlantModel model = PlantModelOf(truth);
  model.duty_map = DriverMapOf(config);
  return model;
}

}  // namespace stewart
