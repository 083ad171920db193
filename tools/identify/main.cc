// stewart_identify: the platform's mass properties (with its payload) from a
// short excitation run of the stack, written as a config overlay
// (docs/hardware.md, "Identify the platform and its payload"), or the
// DC-motor legs' parameters from a bring-up procedure (docs/hardware.md,
// "Identify the actuators"; actuator_mode.h).
//
//   stewart_identify --mode payload --plant sim --truth payload.yaml --out identified.yaml
//   stewart_identify --mode payload --log runs/<run>/log.lcm --out identified.yaml
//   stewart_identify --mode actuators --plant hw --overlay config/overlays/p16p.yaml --out
//   motors.yaml
//   stewart_identify --mode pots --plant hw --overlay config/overlays/p16p.yaml --out pots.yaml
#include <spdlog/spdlog.h>
#include <sys/wait.h>

#include <CLI/CLI.hpp>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>

#include "actuator_mode.h"
#include "log_samples.h"
#include "stewart/config/config_loader.h"
#include "stewart/identify/inertial_fit.h"
#include "stewart/identify/overlay_writer.h"
#include "stewart/identify/platform_estimate.h"
#include "stewart/model/dc_motor.h"
#include "stewart/node/exit_code.h"

namespace fs = std::filesystem;
using stewart::ExitCode;
using stewart::ToInt;

namespace {

struct Options {
  std::string mode;
  std::string plant = "sim";
  bool device_emulator = false;
  std::string out_path;
  std::string config_path;
  std::vector<std::string> overlay_paths;
  std::string truth_path;
  std::string seed;
  std::string scenario = "identify";
  std::string duration_s;
  std::string run_dir;
  std::string lcm_url;
  std::string log_path;
  std::string state_source = "estimate";
  double window_s = stewart::identify::InertialFitOptions{}.window_s;
};

std::string ShellQuote(const std::string& s) {
  std::string quoted = "'";
  for (const char ch : s) quoted += ch == '\'' ? std::string("'\\''") : std::string(1, ch);
  return quoted + "'";
}

std::string Now(const char* format) {
  const std::time_t t = std::time(nullptr);
  char text[64];
  std::strftime(text, sizeof text, format, std::localtime(&t));
  return text;
}

// The excitation run: tools/launch.sh of the source tree this tool was built
// from, on this build, recorded, without a report. Returns the run folder.
std::string RunExcitation(const Options& o) {
  const std::string run_dir = o.run_dir.empty() ? std::string(STEWART_SOURCE_DIR) + "/runs/" +
                                                      Now("%Y%m%d-%H%M%S") + "-identify"
                                                : fs::absolute(o.run_dir).string();
  const char* build_env = std::getenv("STEWART_BUILD_DIR");
  std::string command =
      "cd " + ShellQuote(STEWART_SOURCE_DIR) +
      " && STEWART_BUILD_DIR=" + ShellQuote(build_env ? build_env : STEWART_BUILD_DIR) +
      " tools/launch.sh --no-build --no-report --plant " + ShellQuote(o.plant) + " --scenario " +
      ShellQuote(o.scenario) + " --out " + ShellQuote(run_dir);
  // The estimator must not assume the mass properties being identified
  // (config/overlays/identify.yaml); the user's overlays come after it.
  command += " --overlay " +
             ShellQuote(std::string(STEWART_SOURCE_DIR) + "/config/overlays/identify.yaml");
  for (const std::string& overlay : o.overlay_paths) {
    command += " --overlay " + ShellQuote(fs::absolute(overlay).string());
  }
  if (!o.config_path.empty())
    command += " --config " + ShellQuote(fs::absolute(o.config_path).string());
  if (!o.truth_path.empty())
    command += " --truth " + ShellQuote(fs::absolute(o.truth_path).string());
  if (!o.seed.empty()) command += " --seed " + ShellQuote(o.seed);
  if (!o.duration_s.empty()) command += " --duration " + ShellQuote(o.duration_s);
  if (!o.lcm_url.empty()) command += " --lcm-url " + ShellQuote(o.lcm_url);
  if (o.device_emulator) command += " --device-emulator";
  spdlog::info("excitation: {}", command);
  const int status = std::system(command.c_str());
  const int code = status == -1 ? -1 : (WIFEXITED(status) ? WEXITSTATUS(status) : 128);
  if (code != 0) {
    throw stewart::identify::IdentificationError(
        "the excitation run failed (tools/launch.sh exit " + std::to_string(code) +
        "); its process logs are in " + run_dir);
  }
  return run_dir;
}

// The config the run used: the run folder's config.yaml (overlays merged),
// unless --config names another.
stewart::StackConfig RunConfig(const Options& o, const std::string& log_path) {
  if (!o.config_path.empty()) return stewart::LoadStackConfig(o.config_path, o.overlay_paths);
  const fs::path beside = fs::path(log_path).parent_path() / "config.yaml";
  if (fs::exists(beside)) return stewart::LoadStackConfig(beside.string());
  return stewart::LoadStackConfig(stewart::DefaultConfigPath(), o.overlay_paths);
}

int Identify(const Options& o) {
  std::string log_path = o.log_path;
  std::string provenance;
  if (log_path.empty()) {
    const std::string run_dir = RunExcitation(o);
    log_path = run_dir + "/log.lcm";
    provenance = "stewart_identify --mode payload --plant " + o.plant + ", scenario " + o.scenario +
                 (o.truth_path.empty() ? "" : ", truth " + o.truth_path) + ", run " + run_dir;
  } else {
    provenance = "stewart_identify --mode payload on the log " + log_path;
  }
  const stewart::StackConfig config = RunConfig(o, log_path);
  const std::string& state_channel = o.state_source == "truth" ? config.lcm.channels.state_truth
                                                               : config.lcm.channels.state_estimate;
  const stewart::identify::LogSamples log =
      stewart::identify::ReadLogSamples(log_path, state_channel, config.lcm.channels.command_safe);
  spdlog::info(
      "{}: {} states on {} ({} unusable, {} without a recorded command, {} answered with the "
      "actuators off), {} safe commands; {} paired samples",
      log_path, log.states, state_channel, log.unusable_states, log.unanswered_states,
      log.drive_off_states, log.commands, log.samples.size());
  stewart::identify::InertialFitOptions fit_options;
  fit_options.window_s = o.window_s;
  const stewart::identify::InertialFit fit = stewart::identify::FitInertialParameters(
      config.platform, ModelLegDampingNspm(config.actuators), log.samples, fit_options);
  const stewart::identify::PlatformEstimate estimate = stewart::identify::EstimatePlatform(fit);
  provenance += "\nstate: " + state_channel + ", identified " + Now("%Y-%m-%d %H:%M") +
                "\napply with: tools/launch.sh --overlay " + o.out_path;
  const std::string overlay = stewart::identify::FormatPlatformOverlay(estimate, fit, provenance);
  std::ofstream out(o.out_path);
  out << overlay;
  if (!out) {
    spdlog::error("cannot write '{}'", o.out_path);
    return ToInt(ExitCode::kFault);
  }
  spdlog::info("mass {:.4f} +- {:.2g} kg, CoM [{:.4f}, {:.4f}, {:.4f}] m; written to {}",
               estimate.values(0), estimate.sigma(0), estimate.values(1), estimate.values(2),
               estimate.values(3), o.out_path);
  std::fputs(overlay.c_str(), stdout);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Identify the platform's mass properties (with its payload) or the DC-motor legs' "
      "parameters as a config overlay"};
  Options o;
  stewart::identify::ActuatorModeOptions a;
  app.add_option("--mode", o.mode,
                 "what to identify: payload (the platform body with its load) | actuators (the "
                 "DC-motor legs, bring-up, before the filter is armed) | pots (the legs' pot "
                 "calibration at the stroke ends, bring-up, --plant hw)")
      ->required()
      ->check(CLI::IsMember({"payload", "actuators", "pots"}));
  app.add_option("--out", o.out_path, "overlay file to write")->required();
  app.add_option("--plant", o.plant, "sim | hw (the excitation run's plant)")
      ->check(CLI::IsMember({"sim", "hw"}))
      ->capture_default_str();
  app.add_flag("--device-emulator", o.device_emulator, "with --plant hw: the device emulator");
  app.add_option("-c,--config", o.config_path, "stack config (default: config/platform.yaml)")
      ->check(CLI::ExistingFile);
  app.add_option("--overlay", o.overlay_paths, "config overlay (repeatable, applied in order)")
      ->check(CLI::ExistingFile);
  app.add_option("--truth", o.truth_path, "simulated plant's physics (sim or the emulator)")
      ->check(CLI::ExistingFile);
  app.add_option("--seed", o.seed, "sensor noise seed of the simulated plant");
  app.add_option("--scenario", o.scenario, "excitation scenario, name or file")
      ->capture_default_str();
  app.add_option("--duration", o.duration_s, "seconds (default: the scenario's)");
  app.add_option("--run-dir", o.run_dir, "run folder (default: runs/<date>-identify)");
  app.add_option("--lcm-url", o.lcm_url, "LCM URL of the run (default: a private one)");
  app.add_option("--log", o.log_path, "fit this recorded log instead of running the stack")
      ->check(CLI::ExistingFile);
  app.add_option("--state", o.state_source,
                 "estimate (STATE_EST, as on the hardware) | truth (STATE_TRUE, simulation only)")
      ->check(CLI::IsMember({"estimate", "truth"}))
      ->capture_default_str();
  app.add_option("--window", o.window_s, "integration window of the fit (s)")
      ->check(CLI::Range(0.01, 5.0))
      ->capture_default_str();
  // --mode actuators only.
  app.add_flag("--in-process", a.in_process,
               "actuators, with --plant hw --device-emulator: the emulator behind hw_bridge's "
               "library in this process (no LCM)");
  app.add_flag("--bridge-running", a.bridge_running,
               "actuators, --plant hw: use the hw_bridge --bringup already on the LCM URL");
  app.add_option("--device-port", a.device_port,
                 "actuators, --plant hw: the device's UDP port (default hw_bridge.device_port)")
      ->check(CLI::Range(0, 65535));
  app.add_option("--local-port", a.local_port,
                 "actuators, --plant hw: the bridge's UDP port (default hw_bridge.local_port)")
      ->check(CLI::Range(0, 65535));
  app.add_option("--legs", a.legs, "actuators: the legs to identify (default all)")
      ->check(CLI::Range(0, 5))
      ->delimiter(',');
  app.add_option("--repeats", a.repeats, "actuators: the excursions, this many times")
      ->check(CLI::Range(1, 20))
      ->capture_default_str();
  app.add_option("--excursion", a.excursion_m, "actuators: each excursion's length (m, 0.008)")
      ->check(CLI::Range(0.002, 0.05));
  app.add_option("--max-duty", a.max_duty, "actuators: |duty| limit (default hw_bridge.max_duty)")
      ->check(CLI::Range(0.05, 1.0));
  app.add_option("--guard-margin", a.guard_margin_m,
                 "actuators: the guard's end zone (m; default safety.leg_stroke.margin_m)")
      ->check(CLI::PositiveNumber);
  app.add_option("--speed-cap", a.speed_cap_mps,
                 "actuators: the guard's leg speed cap (m/s; default twice the full-duty speed "
                 "of actuators.motor)")
      ->check(CLI::PositiveNumber);
  app.add_option("--coulomb-sigma", a.coulomb_sigma_n,
                 "actuators: one sigma of the assumed coulomb_friction_n (N; default its value)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--sample-timeout", a.sample_timeout_s,
                 "actuators, --plant hw: no sample for this long ends the run (s)")
      ->check(CLI::Range(0.1, 60.0))
      ->capture_default_str();
  app.add_option("--end-search", a.end_search_m,
                 "pots: how far beyond a nominal stroke end a reading may go (m, 0.004)")
      ->check(CLI::Range(0.0015, 0.02));
  app.add_option("--travel-speed", a.travel_speed_mps,
                 "pots: the legs' common speed between the ends (m/s, 0.01; slower near them)")
      ->check(CLI::Range(0.003, 0.03));
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help exits 0 through CLI11; a bad flag is bad input, as for every node.
    const int status = app.exit(e);
    return status == 0 ? ToInt(ExitCode::kOk) : ToInt(ExitCode::kBadInput);
  }
  try {
    if (o.mode == "actuators" || o.mode == "pots") {
      a.plant = o.plant;
      a.device_emulator = o.device_emulator;
      a.out_path = o.out_path;
      a.config_path = o.config_path;
      a.overlay_paths = o.overlay_paths;
      a.truth_path = o.truth_path;
      a.seed = o.seed;
      a.lcm_url = o.lcm_url;
      a.run_dir = o.run_dir;
      return o.mode == "pots" ? stewart::identify::IdentifyPots(a)
                              : stewart::identify::IdentifyActuators(a);
    }
    return Identify(o);
  } catch (const stewart::InputError& e) {
    spdlog::error("{}", e.what());
    return ToInt(ExitCode::kBadInput);
  } catch (const std::exception& e) {
    spdlog::error("stewart_identify: {}", e.what());
    return ToInt(ExitCode::kFault);
  }
}
