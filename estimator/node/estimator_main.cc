// estimator: EKF state estimate from the platform's sensors (docs/estimator.md).
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <exception>

#include "estimator_node.h"
#include "stewart/node/lcm_handle.h"
#include "stewart/node/node_options.h"
#include "stewart/node/stop_signal.h"

int main(int argc, char** argv) {
  CLI::App app{"estimator: EKF fusing leg potentiometers and IMU into state_t"};
  stewart::NodeOptions options;
  stewart::AddNodeOptions(&app, &options);
  bool perfect_state = false;
  app.add_flag("--perfect-state", perfect_state,
               "republish the simulator's ground truth instead of estimating (testing only)");
  CLI11_PARSE(app, argc, argv);
  const stewart::StackConfig config = stewart::LoadNodeConfigOrExit(options);
  stewart::PrepareForRealTimeIfScheduled("estimator");
  try {
    auto lcm = stewart::MakeLcm(config.lcm.url);
    stewart::InstallStopSignalHandlers();
    stewart::EstimatorNode node(config, lcm.get(), perfect_state || config.estimator.perfect_state);
    spdlog::info("estimator: {} -> {} on {}", config.lcm.channels.sensors,
                 config.lcm.channels.state_estimate, config.lcm.url);
    return node.Run();
  } catch (const std::exception& e) {
    spdlog::error("estimator: {}", e.what());
    return 1;
  }
}
