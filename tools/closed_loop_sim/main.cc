// stewart_closed_loop_sim: the whole control loop in one process, without
// LCM: plant (SUNDIALS) -> sensors -> EKF (or perfect state) -> controller ->
// safety filter -> plant, one control tick per sensor sample, forces held
// between ticks. Deterministic for a seed: the tool for parameter studies and
// Monte-Carlo runs before a change goes to the LCM stack (docs/operations.md).
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <optional>

#include "stewart/config/config_loader.h"
#include "stewart/config/scenario_loader.h"
#include "stewart/config/truth_loader.h"
#include "stewart/controller/scenario.h"
#include "stewart/safety/clp_reference_qp.h"
#include "stewart/stack/closed_loop.h"

int main(int argc, char** argv) {
  using namespace stewart;
  CLI::App app{"Closed-loop simulation of the stack in one process (no LCM)"};
  std::string config_path = DefaultConfigPath();
  std::string scenario_name = "paper";
  std::string csv_path;
  ClosedLoopOptions options;
  std::optional<double> duration_s, k_velocity, k_position;
  std::string variant, truth_path;
  app.add_option("--config", config_path, "stack YAML config")->check(CLI::ExistingFile);
  app.add_option("--scenario", scenario_name, "scenario name or path");
  app.add_option("--duration", duration_s, "seconds (default: the scenario's)");
  app.add_flag("--perfect-state", options.perfect_state, "feed ground truth instead of the EKF");
  app.add_option("--seed", options.seed, "sensor noise seed");
  app.add_option("--k-velocity", k_velocity, "override safety.k_velocity");
  app.add_option("--k-position", k_position, "override safety.k_position");
  app.add_option("--variant", variant, kSafetyVariantNames.Names() + " (qp: Clp reference)");
  app.add_flag("--no-filter", options.no_filter, "pass F_des through (to see what it prevents)");
  bool own_terms = false;
  app.add_flag("--no-shared-terms", own_terms,
               "estimator, controller and filter each evaluate the model themselves "
               "(the same results; to measure what sharing one evaluation saves)");
  app.add_option("--truth", truth_path,
                 "the plant's physics differ from the config (docs/simulation.md, \"Truth\")")
      ->check(CLI::ExistingFile);
  app.add_option("--csv", csv_path, "write t, q, qd, q_est, qd_est, F_des, F*, case per tick");
  CLI11_PARSE(app, argc, argv);

  try {
    StackConfig config = LoadStackConfig(config_path);
    if (k_velocity) config.safety.k_velocity = *k_velocity;
    if (k_position) config.safety.k_position = *k_position;
    if (!variant.empty()) config.safety.variant = ParseSafetyVariant(variant);
    if (!truth_path.empty()) {
      options.truth = LoadPlantTruth(config, truth_path);
      if (const std::string m = TruthLegModelMismatch(config, *options.truth); !m.empty()) {
        spdlog::warn("{}", m);
      }
    }
    const Scenario scenario = LoadScenario(ResolveScenarioPath(scenario_name));
    options.duration_s = duration_s.value_or(scenario.duration_s());
    options.share_model_terms = !own_terms;
    std::unique_ptr<std::ofstream> csv;
    if (!csv_path.empty()) csv = std::make_unique<std::ofstream>(csv_path);
    safety::ClpReferenceQp reference;
    options.reference = &reference;
    const ClosedLoopSummary s = RunClosedLoop(config, scenario, options, csv.get());
    std::printf("%s", FormatSummary(config, s).c_str());
    if (s.model_evaluations > 0) {
      std::printf(
          "model terms: %ld evaluations for estimator, controller and filter, %ld answers "
          "shared\n",
          s.model_evaluations, s.model_evaluations_shared);
    }
    return s.completed ? 0 : 1;
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    return 2;
  }
}
