// stewart_replay: re-runs the safety process (and optionally the controller
// and the estimator) offline on the inputs recorded in a run folder of
// tools/launch.sh, and compares with what the live processes published.
//
//   stewart_replay runs/<run> [--variant V] [--qp-solver clp|alglib]
//       [--k-velocity K] [--k-position K] [--controller] [--estimator]
//       [--json FILE] [--csv FILE] [--expect-identical]
//
// Exit status: 0; 1 with --expect-identical when a replayed output differs
// from the recorded one; 2 on bad input (missing or unreadable log, config,
// scenario; bad flags). docs/operations.md, "Replay".
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>
#include <yaml-cpp/yaml.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "stewart/config/config_loader.h"
#include "stewart/config/scenario_loader.h"
#include "stewart/controller/scenario.h"
#include "stewart/safety/clp_reference_qp.h"
#include "stewart/stack/replay.h"
#include "stewart/stack/replay_output.h"
#ifdef STEWART_HAVE_ALGLIB
#include "stewart/safety/alglib_reference_qp.h"
#endif

namespace stewart::replay {
namespace {

namespace fs = std::filesystem;

struct Options {
  std::string run;
  std::string log_path;
  std::string config_path;
  std::string scenario_path;
  std::string variant;
  std::string qp_solver = "clp";
  std::optional<double> k_velocity;
  std::optional<double> k_position;
  bool force_limits = false;
  std::optional<std::string> channel_suffix;
  bool controller = false;
  bool estimator = false;
  std::string json_path;
  std::string csv_path;
  bool expect_identical = false;
};

std::string RequireFile(const std::string& path, const std::string& what, const char* flag) {
  if (!fs::is_regular_file(path)) {
    throw InputError(fmt::format("no {} '{}' (pass {} FILE)", what, path, flag));
  }
  return path;
}

/// The variant launch.sh gave the safety node (run.yaml `variant:`), if any.
std::optional<std::string> RunVariant(const std::string& run_dir) {
  const std::string path = run_dir + "/run.yaml";
  if (!fs::is_regular_file(path)) return std::nullopt;
  try {
    const YAML::Node run = YAML::LoadFile(path);
    if (!run["variant"]) return std::nullopt;
    const std::string v = run["variant"].as<std::string>();
    if (v.empty() || v == "from config") return std::nullopt;
    return v;
  } catch (const YAML::Exception& e) {
    spdlog::warn("cannot read {}: {}; the variant comes from the config", path, e.what());
    return std::nullopt;
  }
}

std::unique_ptr<safety::ReferenceQpSolver> MakeReference(const std::string& name) {
  if (name == "clp") return std::make_unique<safety::ClpReferenceQp>();
#ifdef STEWART_HAVE_ALGLIB
  if (name == "alglib") return std::make_unique<safety::AlglibReferenceQp>();
#else
  if (name == "alglib") {
    throw InputError("--qp-solver alglib: this build has no ALGLIB (STEWART_WITH_ALGLIB)");
  }
#endif
  throw InputError("--qp-solver must be clp or alglib, not '" + name + "'");
}

void WriteFile(const std::string& path, const std::string& what,
               const std::function<void(std::ostream&)>& write) {
  std::ofstream out(path);
  if (out) write(out);
  if (!out) throw InputError(fmt::format("cannot write the {} '{}'", what, path));
}

int Run(const Options& options) {
  // The run folder, or a log file inside one.
  if (!fs::exists(options.run)) {
    throw InputError("no run folder or LCM log '" + options.run + "'");
  }
  ReplayReport report;
  const bool run_is_log = fs::is_regular_file(options.run);
  report.run_dir = run_is_log ? fs::path(options.run).parent_path().string() : options.run;
  if (report.run_dir.empty()) report.run_dir = ".";
  report.log_path = !options.log_path.empty() ? options.log_path
                    : run_is_log              ? options.run
                                              : report.run_dir + "/log.lcm";
  RequireFile(report.log_path, "LCM log", "--log");
  report.config_path =
      !options.config_path.empty() ? options.config_path : report.run_dir + "/config.yaml";
  RequireFile(report.config_path, "config", "--config");

  StackConfig config;
  try {
    config = LoadStackConfig(report.config_path);
  } catch (const std::exception& e) {
    throw InputError(fmt::format("bad config '{}': {}", report.config_path, e.what()));
  }
  if (options.channel_suffix) SetChannelSuffix(&config.lcm, *options.channel_suffix);

  // The filter to replay: --variant, else launch.sh's --variant, else the config's.
  report.variant_source = "config";
  try {
    if (!options.variant.empty()) {
      config.safety.variant = ParseSafetyVariant(options.variant);
      report.variant_source = "--variant";
    } else if (const auto run_variant = RunVariant(report.run_dir)) {
      config.safety.variant = ParseSafetyVariant(*run_variant);
      report.variant_source = "run.yaml";
    }
  } catch (const std::invalid_argument& e) {
    throw InputError(e.what());
  }
  if (options.qp_solver != "clp" && config.safety.variant != SafetyVariant::kQpReference) {
    spdlog::warn("--qp-solver {} has no effect: the variant is {}", options.qp_solver,
                 ToString(config.safety.variant));
  }
  if (options.k_velocity) {
    if (!(*options.k_velocity > 0.0)) throw InputError("--k-velocity must be positive");
    config.safety.k_velocity = *options.k_velocity;
  }
  if (options.k_position) {
    if (!(*options.k_position > 0.0)) throw InputError("--k-position must be positive");
    config.safety.k_position = *options.k_position;
  }
  if (options.force_limits) config.safety.force_limits_enabled = true;

  std::optional<Scenario> scenario;
  if (options.controller) {
    report.scenario_path =
        !options.scenario_path.empty() ? options.scenario_path : report.run_dir + "/scenario.yaml";
    RequireFile(report.scenario_path, "scenario", "--scenario");
    try {
      scenario = LoadScenario(report.scenario_path);
    } catch (const std::exception& e) {
      throw InputError(fmt::format("bad scenario '{}': {}", report.scenario_path, e.what()));
    }
  }

  const RecordedLog log = ReadLog(report.log_path, config.lcm.channels);
  report.log = &log;
  auto require = [&](bool present, const std::string& channel) {
    if (!present) {
      throw InputError(
          fmt::format("no decodable message on {} in '{}' (another config or channel suffix?)",
                      channel, report.log_path));
    }
  };
  require(!log.nominal.empty(), config.lcm.channels.command_nominal);
  require(!log.estimates.empty(), config.lcm.channels.state_estimate);
  if (options.estimator) {
    if (config.estimator.perfect_state) {
      require(!log.truth.empty(), config.lcm.channels.state_truth);
    } else {
      require(!log.sensors.empty(), config.lcm.channels.sensors);
    }
  }

  const auto reference = MakeReference(options.qp_solver);
  try {
    report.safety = ReplaySafety(config, log, reference.get());
  } catch (const std::invalid_argument& e) {
    throw InputError(fmt::format("cannot build the safety filter: {}", e.what()));
  }
  if (options.controller) report.controller = ReplayController(config, *scenario, log);
  if (options.estimator) report.estimator = ReplayEstimator(config, log);

  std::fputs(FormatSummary(report).c_str(), stdout);
  std::fflush(stdout);
  if (!options.json_path.empty()) {
    WriteFile(options.json_path, "JSON file",
              [&](std::ostream& out) { out << ToJson(report).dump(2) << '\n'; });
  }
  if (!options.csv_path.empty()) {
    WriteFile(options.csv_path, "CSV file",
              [&](std::ostream& out) { WriteSafetyStepsCsv(*report.safety, out); });
  }
  if (report.safety->recorded_variant &&
      *report.safety->recorded_variant != report.safety->variant) {
    spdlog::info("the live filter was {}: the commands are compared across variants",
                 ToString(*report.safety->recorded_variant));
  }
  if (options.expect_identical) {
    if (report.Compared() == 0) {
      spdlog::error("--expect-identical: nothing was compared");
      return 1;
    }
    if (report.Differing() > 0) {
      spdlog::error("--expect-identical: {} of {} replayed outputs differ from the recorded ones",
                    report.Differing(), report.Compared());
      return 1;
    }
  }
  return 0;
}

}  // namespace
}  // namespace stewart::replay

int main(int argc, char** argv) {
  // Diagnostics on stderr: stdout carries the summary only.
  spdlog::set_default_logger(spdlog::stderr_color_mt("stewart_replay"));
  spdlog::set_pattern("stewart_replay: %^%l%$: %v");

  stewart::replay::Options o;
  CLI::App app{
      "Re-run the safety process (and the controller, the estimator) offline on the inputs "
      "recorded by tools/launch.sh and compare with the recorded outputs"};
  app.add_option("run", o.run, "run folder of tools/launch.sh (or its log.lcm)")->required();
  CLI::Option_group* inputs = app.add_option_group("Inputs", "what the run recorded");
  inputs->add_option("--log", o.log_path, "LCM log (default: <run>/log.lcm)");
  inputs->add_option("--config", o.config_path, "stack config (default: <run>/config.yaml)");
  inputs->add_option("--scenario", o.scenario_path,
                     "scenario for --controller (default: <run>/scenario.yaml)");
  inputs->add_option("--channel-suffix", o.channel_suffix,
                     "channel suffix the run used (default: lcm.channel_suffix of the config)");
  CLI::Option_group* filter = app.add_option_group("Safety filter", "the filter to replay");
  filter->add_option(
      "--variant", o.variant,
      stewart::kSafetyVariantNames.Names() + " (default: the run's, run.yaml, else the config's)");
  filter->add_option("--qp-solver", o.qp_solver,
                     "reference QP solver for variant qp: clp | alglib");
  filter->add_option("--k-velocity", o.k_velocity, "override safety.k_velocity");
  filter->add_option("--k-position", o.k_position, "override safety.k_position");
  filter->add_flag("--force-limits", o.force_limits,
                   "also enforce |F_i| <= actuators.force_limit_n (as safety --force-limits)");
  CLI::Option_group* also = app.add_option_group("Other processes", "replayed besides safety");
  also->add_flag("--controller", o.controller,
                 "also replay the controller on the recorded estimates");
  also->add_flag("--estimator", o.estimator,
                 "also replay the estimator on the recorded sensors and safe commands");
  CLI::Option_group* outputs = app.add_option_group("Outputs");
  outputs->add_option("--json", o.json_path, "write the numbers as JSON to FILE");
  outputs->add_option("--csv", o.csv_path,
                      "write every safe command the replayed safety process published to FILE");
  outputs->add_flag("--expect-identical", o.expect_identical,
                    "exit 1 unless every replayed output is bit-identical to the recorded one");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : 2;
  }
  try {
    return stewart::replay::Run(o);
  } catch (const stewart::replay::InputError& e) {
    spdlog::error("{}", e.what());
    return 2;
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 2;
  }
}
