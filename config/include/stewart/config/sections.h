#pragma once
// The parsers of the config's sections, each into the parameter struct of the
// library it configures. Every failure throws ConfigError naming the key.
#include <string>

#include "stewart/config/config_node.h"
#include "stewart/controller/controller_config.h"
#include "stewart/estimator/estimator_config.h"
#include "stewart/guard/guard_config.h"
#include "stewart/hw_bridge/hw_bridge_config.h"
#include "stewart/model/actuator_params.h"
#include "stewart/model/platform_params.h"
#include "stewart/model/sensor_params.h"
#include "stewart/node/lcm_config.h"
#include "stewart/plant_sim/plant_sim_config.h"
#include "stewart/safety/safety_config.h"
#include "stewart/safety/supervisor.h"

namespace stewart {

/// `platform`, `legs` and the geometric part of `actuators`: the model's parameters.
PlatformParams ParsePlatformParams(const ConfigNode& root);
ActuatorConfig ParseActuatorConfig(const ConfigNode& actuators);
SensorConfig ParseSensorConfig(const ConfigNode& sensors);
ControllerConfig ParseControllerConfig(const ConfigNode& controller);
SafetyConfig ParseSafetyConfig(const ConfigNode& safety);
EstimatorConfig ParseEstimatorConfig(const ConfigNode& estimator);
PlantSimConfig ParsePlantSimConfig(const ConfigNode& plant_sim);
/// `actuators` decides the drive map's source: actuators.motor for a DC motor.
HwBridgeConfig ParseHwBridgeConfig(const ConfigNode& hw_bridge, const ActuatorConfig& actuators);
LcmConfig ParseLcmConfig(const ConfigNode& lcm, const ConfigNode& rates);
/// `guard`: what the actuators accept and where they stop on their own.
GuardConfig ParseGuardConfig(const ConfigNode& guard);
safety::SupervisorConfig ParseSupervisorConfig(const ConfigNode& supervisor);

}  // namespace stewart
