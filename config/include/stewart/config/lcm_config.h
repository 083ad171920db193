#pragma once
#include <string>

#include "stewart/config/config_node.h"

namespace stewart {

/// Full channel names: lcm.channel_prefix + lcm.channels.<name> + suffix.
struct ChannelNames {
  std::string sensors;
  std::string state_estimate;
  std::string state_truth;
  std::string setpoint;
  std::string command_nominal;
  std::string command_safe;
  std::string safety_diagnostics;
  std::string health;
};

/// `lcm` and `rates`.
struct LcmConfig {
  std::string url;
  std::string channel_prefix;
  std::string channel_suffix;
  ChannelNames channels;
  double health_rate_hz = 2.0;
};

LcmConfig ParseLcmConfig(const ConfigNode& lcm, const ConfigNode& rates);

/// Applies a new suffix to every channel (two stacks on one network).
void SetChannelSuffix(LcmConfig* lcm, const std::string& suffix);

}  // namespace stewart
