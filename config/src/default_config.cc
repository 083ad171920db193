#include "stewart/config/default_config.h"

namespace stewart {

const StackConfig& DefaultStackConfig() {
  static const StackConfig config = LoadStackConfig(DefaultConfigPath());
  return config;
}

std::string DcMotorOverlayPath() {
  return std::string(STEWART_SOURCE_DIR) + "/config/overlays/p16p.yaml";
}

const StackConfig& DcMotorStackConfig() {
  static const StackConfig config = LoadStackConfig(DefaultConfigPath(), {DcMotorOverlayPath()});
  return config;
}

}  // namespace stewart
