#include "stewart/config/default_config.h"

namespace stewart {

const StackConfig& DefaultStackConfig() {
  static const StackConfig config = LoadStackConfig(DefaultConfigPath());
  return config;
}

}  // namespace stewart
