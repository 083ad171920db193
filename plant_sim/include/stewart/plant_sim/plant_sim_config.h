#pragma once
#include <string>

#include "stewart/model/types.h"

namespace stewart {

/// `plant_sim`: the simulator's integrator and modes (docs/simulation.md).
struct PlantSimConfig {
  /// SUNDIALS method: arkode_erk (explicit RK, order 5) | cvode_bdf | cvode_adams.
  std::string integrator = "arkode_erk";
  double rel_tol = 1e-8;
  double abs_tol = 1e-10;
  /// A safe command whose sample is older than this (stack time, against
  /// the newest published sample) is never applied (s).
  double command_timeout_s = 0.05;
  double lockstep_timeout_s = 5.0;
  Vector6d initial_pose = Vector6d::Zero();
  Vector6d initial_velocity = Vector6d::Zero();
};

}  // namespace stewart
