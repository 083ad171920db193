#pragma once
#include "stewart/config/default_config.h"

namespace stewart::hw::test {

/// The project's config file: tests use the shipped calibration and map.
inline const StackConfig& Config() { return DefaultStackConfig(); }

}  // namespace stewart::hw::test
