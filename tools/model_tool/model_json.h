#pragma once
// JSON in and out for the model tool.
#include <nlohmann/json.hpp>

#include "stewart/model/actuator_params.h"
#include "stewart/model/platform_params.h"
#include "stewart/model/types.h"

namespace stewart {

/// One query: pose q, velocity qd (default 0), leg forces F (default 0),
/// acceleration qdd for inverse dynamics (default 0), optional leg lengths
/// for forward kinematics. Throws std::invalid_argument naming a bad field.
struct ModelQuery {
  Vector6d q = Vector6d::Zero();
  Vector6d qd = Vector6d::Zero();
  Vector6d force_n = Vector6d::Zero();
  Vector6d qdd = Vector6d::Zero();
  bool has_leg_lengths = false;
  Vector6d leg_length_m = Vector6d::Zero();
};

ModelQuery ParseModelQuery(const nlohmann::json& in, const Vector6d& default_q);

/// Evaluates everything the model offers for one query.
/// With `actuators`, also what the legs must do: the leg speeds and, per
/// leg, the force the stack commands for qdd at qd (inverse dynamics plus
/// the modelled leg damping, N), its share of the force limit and, for a DC
/// motor, its duty (docs/safety.md, "What the limits ask of the motors").
nlohmann::json EvaluateModelQuery(const PlatformParams& params, const ModelQuery& query,
                                  const ActuatorConfig* actuators = nullptr);

}  // namespace stewart
