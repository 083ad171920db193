#pragma once
// The shipped config, loaded once: for tests and benchmarks.
#include <string>

#include "stewart/config/config_loader.h"

namespace stewart {

/// LoadStackConfig(DefaultConfigPath()), loaded on the first call.
const StackConfig& DefaultStackConfig();

/// The overlay that gives the stack the prototype's P-16P legs
/// (config/overlays/p16p.yaml) and the shipped config with it.
std::string DcMotorOverlayPath();
const StackConfig& DcMotorStackConfig();

}  // namespace stewart
