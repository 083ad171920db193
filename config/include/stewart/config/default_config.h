#pragma once
// The shipped config, loaded once: for tests and benchmarks.
#include "stewart/config/config_loader.h"

namespace stewart {

/// LoadStackConfig(DefaultConfigPath()), loaded on the first call.
const StackConfig& DefaultStackConfig();

}  // namespace stewart
