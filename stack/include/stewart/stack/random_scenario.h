#pragma once
// The campaign's `random` scenario (docs/campaign.md): a random sequence of
// setpoint steps, some inside the configured position limits and some beyond
// them (always inside the actuator stroke), and a random initial state inside
// the safe set.
#include <yaml-cpp/yaml.h>

#include <random>

#include "stewart/config/stack_config.h"
#include "stewart/controller/scenario.h"
#include "stewart/safety/constraint_set.h"

namespace stewart {

struct RandomRun {
  YAML::Node scenario_yaml;  ///< the scenario as a file (config/scenarios format)
  Scenario scenario{"random", 0.0, {}};
  /// Inside the stroke and 5 mm inside every position limit the filter
  /// keeps (the configured ones drawn in by the joints' tolerance).
  Vector6d initial_pose = Vector6d::Zero();
  /// Within half of every velocity limit, and inside the safe set with
  /// initial_pose (InsideSafeSet).
  Vector6d initial_velocity = Vector6d::Zero();
};

/// Draws one random run from `rng` for `config`'s limits and geometry.
RandomRun MakeRandomRun(const StackConfig& config, double duration_s, std::mt19937_64* rng);

/// Whether (q, qd) is inside the safe set the filter keeps with
/// `constraints`: every energy barrier h_D = alpha_e h - 1/2 qd^T M qd (axis
/// limits and leg strokes; J) and every velocity limit's h_v (m/s) is
/// non-negative (docs/safety.md, "Method"), M from `platform`'s model.
bool InsideSafeSet(const PlatformParams& platform, const safety::ConstraintSet& constraints,
                   const Vector6d& q, const Vector6d& qd);

}  // namespace stewart
