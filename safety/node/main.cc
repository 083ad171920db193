// safety: the CBF safety filter as a process.
//   safety [--variant closed_form|paper|qp|uncomposed] [--force-limits] [-c config.yaml] [--lcm-url
//   URL]
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <memory>

#include "safety_node.h"
#include "stewart/node/lcm_handle.h"
#include "stewart/node/node_options.h"
#include "stewart/node/stop_signal.h"
#include "stewart/safety/clp_reference_qp.h"

int main(int argc, char** argv) {
  CLI::App app{"CBF safety filter: STATE_EST + CMD_NOMINAL -> CMD_SAFE + SAFETY_DIAG"};
  stewart::NodeOptions options;
  stewart::AddNodeOptions(&app, &options);
  std::string variant;
  bool force_limits = false;
  app.add_option("--variant", variant,
                 "closed_form | paper | qp | uncomposed (default: safety.variant)");
  app.add_flag("--force-limits", force_limits, "also enforce |F_i| <= actuators.force_limit_n");
  CLI11_PARSE(app, argc, argv);
  stewart::StackConfig config = stewart::LoadNodeConfigOrExit(options);
  stewart::PrepareForRealTimeIfScheduled("safety");
  try {
    if (!variant.empty()) config.safety.variant = stewart::ParseSafetyVariant(variant);
  } catch (const std::invalid_argument& e) {
    spdlog::error("{}", e.what());
    return 2;
  }
  if (force_limits) config.safety.force_limits_enabled = true;
  stewart::InstallStopSignalHandlers();
  try {
    auto lcm = stewart::MakeLcm(config.lcm.url);
    stewart::safety::ClpReferenceQp reference;
    stewart::SafetyNode node(config, lcm.get(), &reference);
    spdlog::info("safety: variant {}, {} -> {} on {}", stewart::ToString(config.safety.variant),
                 config.lcm.channels.command_nominal, config.lcm.channels.command_safe,
                 config.lcm.url);
    return node.Run();
  } catch (const std::exception& e) {
    spdlog::error("safety: {}", e.what());
    return 1;
  }
}
