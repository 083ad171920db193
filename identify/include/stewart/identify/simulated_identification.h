#pragma once
// The actuator identification against plant_sim's Plant, start to end: the
// default bring-up procedure, the fit and the overlay it writes
// (stewart_identify --mode actuators --plant sim; docs/hardware.md,
// "Identify the actuators"). For campaigns and tests that close the loop on
// identified motors.
#include <string>

#include "stewart/config/stack_config.h"
#include "stewart/plant_sim/truth.h"

namespace stewart::identify {

/// Identifies the DC-motor legs of `truth` (the platform at rest at its
/// initial pose) with the stack's `config` (actuators.model dc_motor) and
/// returns the config overlay with the identified actuators.motor keys.
/// Throws GuardTrip if the guard stopped the procedure, std::runtime_error
/// if the fit cannot be made.
std::string IdentifyActuatorsInSimulation(const StackConfig& config, const PlantTruth& truth,
                                          const std::string& provenance);

}  // namespace stewart::identify
