#pragma once
#include "stewart/config/config_loader.h"

namespace stewart::hw::test {

/// The project's config file: tests use the shipped calibration and map.
inline const StackConfig& Config() {
  static const StackConfig config = LoadStackConfig(DefaultConfigPath());
  return config;
}

}  // namespace stewart::hw::test
