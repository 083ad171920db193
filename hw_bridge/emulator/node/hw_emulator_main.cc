// hw_emulator: the device side of the wire protocol on plant_sim's plant
// model (EmulatorNode). It runs without LCM: only --lcm-url turns on the
// ground truth.
#include <spdlog/spdlog.h>

#include "emulator_node.h"
#include "stewart/config/truth_loader.h"
#include "stewart/node/node_main.h"

int main(int argc, char** argv) {
  stewart::EmulatorOptions options;
  bool no_noise = false;
  CLI::Option* lcm_url = nullptr;
  std::string truth_path;
  stewart::PlantTruth truth;
  return stewart::NodeMain(
      argc, argv,
      {"hw_emulator",
       "hw_emulator: the device side of the wire protocol on plant_sim's plant model",
       /*needs_lcm=*/false},
      [&](CLI::App& app) {
        app.add_option("--transport", options.transport, "udp | pty")
            ->check(CLI::IsMember({"udp", "pty"}))
            ->capture_default_str();
        app.add_option("--pty-link", options.pty_link,
                       "pty: create this symlink to the slave device");
        app.add_option("--bind-host", options.bind_host,
                       "udp: address to bind (default hw_bridge.device_host)");
        app.add_option("--device-port", options.device_port,
                       "udp: port to bind (default hw_bridge.device_port)");
        app.add_option("--host", options.host,
                       "udp: bridge address (default hw_bridge.local_host)");
        app.add_option("--host-port", options.host_port,
                       "udp: bridge port (default hw_bridge.local_port)");
        app.add_option("--rate-hz", options.rate_hz, "sample rate (default sensors.rate_hz)");
        app.add_option("--duration-s", options.duration_s,
                       "stop after this long (0: until SIGINT/SIGTERM)");
        app.add_option("--drop-every", options.drop_every,
                       "drop every Nth sensor frame (link tests)");
        app.add_flag("--no-noise", no_noise, "noise- and bias-free sensors");
        app.add_option("--truth", truth_path,
                       "YAML overriding the emulated platform's physics (docs/simulation.md, "
                       "\"Truth\"); default: the config's values")
            ->check(CLI::ExistingFile);
        // The shared --lcm-url, with this process's meaning: without it, no LCM at all.
        lcm_url = app.get_option("--lcm-url");
        lcm_url->description(
            "publish the ground truth (state_t, evaluation only) on this LCM URL; default: none");
      },
      [&](stewart::StackConfig& config) -> std::optional<stewart::ExitCode> {
        if (lcm_url->count() == 0) config.lcm.url.clear();
        if (options.rate_hz <= 0.0) options.rate_hz = config.sensors.rate_hz;
        stewart::EmulatorPeriodUs(options.rate_hz);
        options.noise = !no_noise;
        truth = stewart::LoadPlantTruth(config, truth_path);
        if (const std::string m = stewart::TruthLegModelMismatch(config, truth); !m.empty()) {
          spdlog::warn("hw_emulator: {}", m);
        }
        return std::nullopt;
      },
      [&](const stewart::StackConfig& config, lcm::LCM* lcm) {
        stewart::EmulatorNode node(config, truth, lcm, options);
        spdlog::info("hw_emulator: physics from {}",
                     truth_path.empty() ? "the config" : "truth " + truth_path);
        return node.Run();
      });
}
