#pragma once
// The campaign's `random` scenario (docs/campaign.md): a random sequence of
// setpoint steps, some inside the configured position limits and some beyond
// them (always inside the actuator stroke), and a random initial state inside
// the safe set.
#include <yaml-cpp/yaml.h>

#include <random>

#include "stewart/config/stack_config.h"
#include "stewart/controller/scenario.h"

namespace stewart {

struct RandomRun {
  YAML::Node scenario_yaml;  ///< the scenario as a file (config/scenarios format)
  Scenario scenario{"random", 0.0, {}};
  /// Inside the stroke and 5 mm inside every position limit the filter
  /// keeps (the configured ones drawn in by the joints' tolerance).
  Vector6d initial_pose = Vector6d::Zero();
  Vector6d initial_velocity = Vector6d::Zero();  ///< within half of every velocity limit
};

/// Draws one random run from `rng` for `config`'s limits and geometry.
RandomRun MakeRandomRun(const StackConfig& config, double duration_s, std::mt19937_64* rng);

}  // namespace stewart
