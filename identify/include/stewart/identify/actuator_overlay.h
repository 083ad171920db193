#pragma once
// The identified motor values as a config overlay (tools/launch.sh --overlay
// FILE, after config/overlays/p16p.yaml): the actuators.motor keys the fit
// determines, each with its one-sigma uncertainty in a comment, and in
// comments what the fit assumed, the legs' own values and the start duties.
#include <string>

#include "stewart/identify/actuator_fit.h"

namespace stewart::identify {

/// YAML text `actuators: {motor: {dead_band_duty, stall_force_n,
/// no_load_speed_mps, reflected_mass_kg}}`, plus actuators.force_limit_n
/// when the config's exceeds the identified force at full duty (the config
/// loader refuses that). `config` is the stack's actuators the fit ran with;
/// `provenance` (lines without '#') goes first, as comments.
std::string FormatActuatorOverlay(const ActuatorFit& fit, const ActuatorConfig& config,
                                  const ActuatorFitOptions& options, const std::string& provenance);

}  // namespace stewart::identify
