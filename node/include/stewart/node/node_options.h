#pragma once
#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "stewart/config/stack_config.h"

namespace stewart {

/// Flags every node shares: one config, optional LCM URL and channel-suffix
/// overrides (launch.sh gives each run a private URL).
struct NodeOptions {
  std::string config_path;
  std::vector<std::string> overlay_paths;  ///< --overlay, applied to the config in order
  std::string lcm_url;                     ///< "" = lcm.url from the config
  std::string channel_suffix;              ///< "" = lcm.channel_suffix from the config
  std::string log_level = "info";
};

void AddNodeOptions(CLI::App* app, NodeOptions* options);

/// Sets the log level, loads the config and applies the overrides. Throws
/// ConfigError naming the key.
StackConfig LoadNodeConfig(const NodeOptions& options);

/// LoadNodeConfig for tools that are not nodes: on a bad config logs one clear
/// line naming the key and exits with ExitCode::kBadInput.
StackConfig LoadNodeConfigOrExit(const NodeOptions& options);

/// When the process was started with a real-time scheduling policy
/// (SCHED_FIFO/RR, e.g. by tools/launch.sh in real time), locks its memory
/// (mlockall) so no page fault stalls a control tick, and logs the policy.
/// Does nothing under normal scheduling.
void PrepareForRealTimeIfScheduled(const std::string& name);

}  // namespace stewart
