#pragma once
// The simulated plant's physics (docs/simulation.md, "Truth"): the stack
// config's `platform`, `legs`, `actuators` and `sensors`, overridden key by key
// by a truth file, plus what only a truth has (payload, per-joint errors,
// actuator and sensor errors, latency, disturbance, initial state). Only the
// plant (plant_sim, the device emulator, the in-process loops) reads a truth.
#include <yaml-cpp/yaml.h>

#include <string>

#include "stewart/config/config_loader.h"
#include "stewart/config/config_node.h"
#include "stewart/config/stack_config.h"
#include "stewart/plant_sim/truth.h"

namespace stewart {

/// The stack config's file (config.source_path, without the overlays the
/// config may have been loaded with: overlays change what the stack
/// believes, the truth is the plant) overridden by the truth file;
/// TruthOfConfig (the config as loaded, overlays included) when truth_path
/// is empty. The sensors' rate and seed stay the config's: they are how the
/// simulation runs, not physics.
/// Throws ConfigError naming the key ("truth.platform.payload.mass_kg").
PlantTruth LoadPlantTruth(const StackConfig& config, const std::string& truth_path);

/// When the plant's legs are another model than the stack's, what to tell
/// the user; empty when they agree. The usual cause: a truth that does not
/// name `actuators.model`, given with an overlay that does (e.g.
/// config/overlays/p16p.yaml): the truth overrides the file, so the plant
/// gets the file's legs.
std::string TruthLegModelMismatch(const StackConfig& config, const PlantTruth& truth);

/// The same from parsed YAML: `config_root` a whole stack config, `truth`
/// a truth document (a mapping; an empty one gives the config's values).
PlantTruth ParsePlantTruth(const StackConfig& config, const YAML::Node& config_root,
                           const YAML::Node& truth);

}  // namespace stewart
