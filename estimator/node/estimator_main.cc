// estimator: EKF state estimate from the platform's sensors (docs/estimator.md).
#include <spdlog/spdlog.h>

#include "estimator_node.h"
#include "stewart/node/node_main.h"

int main(int argc, char** argv) {
  bool perfect_state = false;
  int64_t lose_seq = -1;
  return stewart::NodeMain(
      argc, argv, {"estimator", "estimator: EKF fusing leg potentiometers and IMU into state_t"},
      [&](CLI::App& app) {
        app.add_flag("--perfect-state", perfect_state,
                     "republish the simulator's ground truth instead of estimating (testing only)");
        app.add_option("--test-lose-seq", lose_seq,
                       "do not publish the estimate with this seq, once, as if the network lost "
                       "it (testing only)");
      },
      [&](stewart::StackConfig& config) -> std::optional<stewart::ExitCode> {
        if (perfect_state) config.estimator.perfect_state = true;
        return std::nullopt;
      },
      [&](const stewart::StackConfig& config, lcm::LCM* lcm) {
        stewart::EstimatorNode node(config, lcm, config.estimator.perfect_state);
        if (lose_seq >= 0) node.LoseEstimateForTest(lose_seq);
        spdlog::info("estimator: {} -> {} on {}", config.lcm.channels.sensors,
                     config.lcm.channels.state_estimate, config.lcm.url);
        return node.Run();
      });
}
