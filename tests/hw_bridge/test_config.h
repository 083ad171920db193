#pragma once
#include "stewart/config/default_config.h"

namespace stewart::hw::test {

/// The project's config file: tests use the shipped calibration and map.
inline const StackConfig& Config() { return DefaultStackConfig(); }
/// The same with the P-16P legs (config/overlays/p16p.yaml).
inline const StackConfig& DcMotorConfig() { return DcMotorStackConfig(); }

}  // namespace stewart::hw::test
