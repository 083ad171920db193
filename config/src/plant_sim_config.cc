#include "stewart/config/sections.h"
#include "stewart/plant_sim/ode_integrator.h"

namespace stewart {

PlantSimConfig ParsePlantSimConfig(const ConfigNode& plant_sim) {
  PlantSimConfig p;
  // Optional: a run's config.yaml without the key (which the replay loads)
  // keeps loading.
  if (plant_sim.Has("integrator")) {
    p.integrator = plant_sim.Choice("integrator", kOdeMethodNames.NameList());
  }
  p.rel_tol = plant_sim.PositiveDouble("rel_tol");
  p.abs_tol = plant_sim.PositiveDouble("abs_tol");
  p.command_timeout_s = plant_sim.PositiveDouble("command_timeout_s");
  // The fallback without a command is always actuators off. The key is
  // optional for older configs; `hold_last` applied commands far older than
  // command_timeout_s and is refused.
  if (plant_sim.Has("timeout_fallback")) {
    plant_sim.Choice("timeout_fallback", {"off"});
  }
  p.lockstep_timeout_s = plant_sim.PositiveDouble("lockstep_timeout_s");
  p.initial_pose = plant_sim.Vec6("initial_pose");
  p.initial_velocity = plant_sim.Vec6("initial_velocity");
  return p;
}

}  // namespace stewart
