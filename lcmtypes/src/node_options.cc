#include "stewart/node/node_options.h"

#include <spdlog/spdlog.h>

#include <cstdlib>

namespace stewart {

void AddNodeOptions(CLI::App* app, NodeOptions* options) {
  options->config_path = DefaultConfigPath();
  app->add_option("-c,--config", options->config_path, "YAML config")->capture_default_str();
  app->add_option("--lcm-url", options->lcm_url, "LCM URL (default: lcm.url of the config)");
  app->add_option("--channel-suffix", options->channel_suffix,
                  "suffix appended to every channel name");
  app->add_option("--log-level", options->log_level, "trace|debug|info|warn|error")
      ->capture_default_str();
}

StackConfig LoadNodeConfigOrExit(const NodeOptions& options) {
  spdlog::set_level(spdlog::level::from_str(options.log_level));
  try {
    StackConfig config = LoadStackConfig(options.config_path);
    if (!options.lcm_url.empty()) config.lcm.url = options.lcm_url;
    if (!options.channel_suffix.empty()) SetChannelSuffix(&config.lcm, options.channel_suffix);
    return config;
  } catch (const ConfigError& e) {
    spdlog::error("{} (file: {})", e.what(), options.config_path);
    std::exit(2);
  }
}

}  // namespace stewart
