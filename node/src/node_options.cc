#include "stewart/node/node_options.h"

#include <sched.h>
#include <spdlog/spdlog.h>
#include <sys/mman.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>

#include "stewart/config/config_loader.h"
#include "stewart/node/exit_code.h"

namespace stewart {

void AddNodeOptions(CLI::App* app, NodeOptions* options) {
  options->config_path = DefaultConfigPath();
  app->add_option("-c,--config", options->config_path, "YAML config")->capture_default_str();
  app->add_option("--overlay", options->overlay_paths,
                  "YAML overlay: its keys replace the config's (repeatable, applied in order)")
      ->check(CLI::ExistingFile);
  app->add_option("--lcm-url", options->lcm_url, "LCM URL (default: lcm.url of the config)");
  app->add_option("--channel-suffix", options->channel_suffix,
                  "suffix appended to every channel name");
  app->add_option("--log-level", options->log_level, "trace|debug|info|warn|error")
      ->capture_default_str();
}

StackConfig LoadNodeConfig(const NodeOptions& options) {
  spdlog::set_level(spdlog::level::from_str(options.log_level));
  StackConfig config = LoadStackConfig(options.config_path, options.overlay_paths);
  if (!options.lcm_url.empty()) config.lcm.url = options.lcm_url;
  if (!options.channel_suffix.empty()) SetChannelSuffix(&config.lcm, options.channel_suffix);
  return config;
}

StackConfig LoadNodeConfigOrExit(const NodeOptions& options) {
  try {
    return LoadNodeConfig(options);
  } catch (const ConfigError& e) {
    spdlog::error("{} (file: {})", e.what(), options.config_path);
    std::exit(ToInt(ExitCode::kBadInput));
  }
}

void PrepareForRealTimeIfScheduled(const std::string& name) {
  const int policy = sched_getscheduler(0);
  if (policy != SCHED_FIFO && policy != SCHED_RR) return;
  sched_param param{};
  sched_getparam(0, &param);
  if (mlockall(MCL_CURRENT | MCL_FUTURE) == 0) {
    spdlog::info("{}: {} priority {}, memory locked", name,
                 policy == SCHED_FIFO ? "SCHED_FIFO" : "SCHED_RR", param.sched_priority);
  } else {
    spdlog::warn("{}: real-time priority {} but mlockall failed ({}): page faults may stall ticks",
                 name, param.sched_priority, std::strerror(errno));
  }
}

}  // namespace stewart
