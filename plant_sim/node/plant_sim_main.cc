// plant_sim: the simulated Stewart platform on LCM (docs/simulation.md).
#include <spdlog/spdlog.h>

#include <vector>

#include "plant_sim_node.h"
#include "stewart/common/check.h"
#include "stewart/config/truth_loader.h"
#include "stewart/node/node_main.h"

namespace {

void ToVector6(const std::vector<double>& v, const char* flag, stewart::Vector6d* out) {
  if (v.empty()) return;
  if (v.size() != 6) {
    throw stewart::InputError(
        flag, "needs 6 values (x y z phi theta psi), got " + std::to_string(v.size()));
  }
  *out = Eigen::Map<const stewart::Vector6d>(v.data());
}

}  // namespace

int main(int argc, char** argv) {
  stewart::PlantSimOptions options;
  std::string mode = "realtime";
  std::vector<double> initial_pose, initial_velocity;
  int64_t seed = -1;
  std::string integrator;
  double rate_hz = 0.0;
  std::string truth_path;
  stewart::PlantTruth truth;
  return stewart::NodeMain(
      argc, argv, {"plant_sim", "plant_sim: the Stewart platform simulated with SUNDIALS, on LCM"},
      [&](CLI::App& app) {
        app.add_option("--mode", mode, "realtime | lockstep")
            ->check(CLI::IsMember({"realtime", "lockstep"}))
            ->capture_default_str();
        app.add_option("--duration", options.duration_s,
                       "simulated seconds to run; 0 = until signal")
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
                       stewart::kOdeMethodNames.Names() + " (default: config)")
            ->check(CLI::IsMember(stewart::kOdeMethodNames.NameList()));
        app.add_option("--rate-hz", rate_hz,
                       "sensor and control tick rate (default: sensors.rate_hz)")
            ->check(CLI::PositiveNumber);
        app.add_option("--truth", truth_path,
                       "YAML overriding the plant's physics (docs/simulation.md, \"Truth\"); "
                       "default: the config's values")
            ->check(CLI::ExistingFile);
        app.add_option("--start-utime", options.start_utime,
                       "utime of tick 0 in us (default: 0 in lockstep, wall clock in real time)");
        app.add_option(
               "--startup-republish", options.startup_republish_s,
               "lockstep: resend tick 0 every this many wall seconds until answered (0 = never)")
            ->check(CLI::NonNegativeNumber)
            ->capture_default_str();
      },
      [&](stewart::StackConfig& config) -> std::optional<stewart::ExitCode> {
        ToVector6(initial_pose, "--initial-pose", &config.plant_sim.initial_pose);
        ToVector6(initial_velocity, "--initial-velocity", &config.plant_sim.initial_velocity);
        if (seed >= 0) config.sensors.seed = static_cast<unsigned>(seed);
        if (!integrator.empty()) config.plant_sim.integrator = integrator;
        if (rate_hz > 0.0) config.sensors.rate_hz = rate_hz;
        options.mode =
            mode == "lockstep" ? stewart::SimMode::kLockstep : stewart::SimMode::kRealTime;
        truth = stewart::LoadPlantTruth(config, truth_path);
        if (const std::string m = stewart::TruthLegModelMismatch(config, truth); !m.empty()) {
          spdlog::warn("plant_sim: {}", m);
        }
        ToVector6(initial_pose, "--initial-pose", &truth.initial_pose);
        ToVector6(initial_velocity, "--initial-velocity", &truth.initial_velocity);
        return std::nullopt;
      },
      [&](const stewart::StackConfig& config, lcm::LCM* lcm) {
        stewart::PlantSimNode node(config, truth, lcm, options);
        spdlog::info("plant_sim: {} mode, {} Hz, integrator {}, lcm {}, truth {}", mode,
                     config.sensors.rate_hz, config.plant_sim.integrator, config.lcm.url,
                     truth_path.empty() ? "= config" : truth_path);
        return node.Run();
      });
}
