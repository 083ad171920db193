// plant_sim: the simulated Stewart platform on LCM (docs/simulation.md).
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <vector>

#include "plant_sim_node.h"
#include "stewart/config/config_loader.h"
#include "stewart/node/node_options.h"
#include "stewart/node/stop_signal.h"

namespace {

bool ToVector6(const std::vector<double>& v, const char* flag, stewart::Vector6d* out) {
  if (v.empty()) return true;
  if (v.size() != 6) {
    spdlog::error("{} needs 6 values (x y z phi theta psi), got {}", flag, v.size());
    return false;
  }
  *out = Eigen::Map<const stewart::Vector6d>(v.data());
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"plant_sim: the Stewart platform simulated with SUNDIALS, on LCM"};
  stewart::NodeOptions node_options;
  stewart::AddNodeOptions(&app, &node_options);
  stewart::PlantSimOptions options;
  std::string mode = "realtime";
  std::vector<double> initial_pose, initial_velocity;
  int64_t seed = -1;
  std::string integrator;
  double rate_hz = 0.0;
  app.add_option("--mode", mode, "realtime | lockstep")
      ->check(CLI::IsMember({"realtime", "lockstep"}))
      ->capture_default_str();
  app.add_option("--duration", options.duration_s, "simulated seconds to run; 0 = until signal")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--seed", seed, "sensor noise seed (default: sensors.seed)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--initial-pose", initial_pose,
                 "x y z phi theta psi (default: plant_sim.initial_pose)")
      ->expected(6);
  app.add_option("--initial-velocity", initial_velocity,
                 "6 values (default: plant_sim.initial_velocity)")
      ->expected(6);
  app.add_option("--integrator", integrator,
                 "arkode_erk | cvode_bdf | cvode_adams (default: config)")
      ->check(CLI::IsMember({"arkode_erk", "cvode_bdf", "cvode_adams"}));
  app.add_option("--rate-hz", rate_hz, "sensor and control tick rate (default: sensors.rate_hz)")
      ->check(CLI::PositiveNumber);
  app.add_option("--start-utime", options.start_utime,
                 "utime of tick 0 in us (default: 0 in lockstep, wall clock in real time)");
  app.add_option("--startup-republish", options.startup_republish_s,
                 "lockstep: resend tick 0 every this many wall seconds until answered (0 = never)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);

  stewart::StackConfig config = stewart::LoadNodeConfigOrExit(node_options);

  stewart::PrepareForRealTimeIfScheduled("plant_sim");
  if (!ToVector6(initial_pose, "--initial-pose", &config.plant_sim.initial_pose) ||
      !ToVector6(initial_velocity, "--initial-velocity", &config.plant_sim.initial_velocity)) {
    return 2;
  }
  if (seed >= 0) config.sensors.seed = static_cast<unsigned>(seed);
  if (!integrator.empty()) config.plant_sim.integrator = integrator;
  if (rate_hz > 0.0) config.sensors.rate_hz = rate_hz;
  try {
    stewart::ValidateStackConfig(config);  // the initial pose must lie inside the stroke
  } catch (const stewart::ConfigError& e) {
    spdlog::error("{}", e.what());
    return 2;
  }
  options.mode = mode == "lockstep" ? stewart::SimMode::kLockstep : stewart::SimMode::kRealTime;

  stewart::InstallStopSignalHandlers();
  try {
    stewart::PlantSimNode node(config, options);
    spdlog::info("plant_sim: {} mode, {} Hz, integrator {}, lcm {}", mode, config.sensors.rate_hz,
                 config.plant_sim.integrator, config.lcm.url);
    return node.Run();
  } catch (const std::exception& e) {
    spdlog::error("plant_sim: {}", e.what());
    return 1;
  }
}
