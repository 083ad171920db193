#pragma once
// The stack's LCM wiring (config sections `lcm` and `rates`): the URL and
// every channel name. Header-only, shared by the nodes, replay and the loader.
#include <string>

#include "stewart/common/time_plausibility.h"

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
  std::string supervisor;        ///< supervisor_state_t: the state and the safety session
  std::string operator_command;  ///< operator_command_t: arm, hold, resume, estop, reset
};

/// `lcm` and `rates`.
struct LcmConfig {
  std::string url;
  std::string channel_prefix;
  std::string channel_suffix;
  ChannelNames channels;
  double health_rate_hz = 2.0;
  /// Key of the authenticated channels (node/message_auth.h); "" = off.
  std::string auth_key_file;
  /// How far a message's stack time may be from its receiver's
  /// (lcm.time_window_s, lcm.max_time_rate; common/time_plausibility.h).
  TimePlausibilityParams time_plausibility;
};

/// Every channel: its config key under lcm.channels and its field.
struct ChannelField {
  const char* key;
  std::string ChannelNames::*member;
};
inline constexpr ChannelField kChannelFields[] = {
    {"sensors", &ChannelNames::sensors},
    {"state_estimate", &ChannelNames::state_estimate},
    {"state_truth", &ChannelNames::state_truth},
    {"setpoint", &ChannelNames::setpoint},
    {"command_nominal", &ChannelNames::command_nominal},
    {"command_safe", &ChannelNames::command_safe},
    {"safety_diagnostics", &ChannelNames::safety_diagnostics},
    {"health", &ChannelNames::health},
    {"supervisor", &ChannelNames::supervisor},
    {"operator", &ChannelNames::operator_command},
};

/// Applies a new suffix to every channel (two stacks on one network).
inline void SetChannelSuffix(LcmConfig* lcm, const std::string& suffix) {
  for (const ChannelField& field : kChannelFields) {
    std::string& name = lcm->channels.*field.member;
    name = name.substr(0, name.size() - lcm->channel_suffix.size()) + suffix;
  }
  lcm->channel_suffix = suffix;
}

}  // namespace stewart
