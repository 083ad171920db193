// controller: the nominal feedback-linearising PD controller (paper eq. 3)
// as an LCM process. See docs/controller.md.
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <iostream>

#include "controller_node.h"
#include "stewart/node/node_options.h"

int main(int argc, char** argv) {
  CLI::App app{"Stewart platform nominal controller: state estimate -> F_des"};
  stewart::NodeOptions node_options;
  stewart::AddNodeOptions(&app, &node_options);
  std::string scenario_name;
  bool exit_at_end = false;
  bool print_duration = false;
  app.add_option("-s,--scenario", scenario_name,
                 "scenario name (config/scenarios/<name>.yaml) or path; "
                 "without one, setpoints come live from the setpoint channel");
  app.add_flag("--exit-at-end", exit_at_end, "exit once the scenario's duration has elapsed");
  app.add_flag("--print-duration", print_duration,
               "print the scenario's duration in seconds and exit");
  CLI11_PARSE(app, argc, argv);
  if ((exit_at_end || print_duration) && scenario_name.empty()) {
    spdlog::error("--exit-at-end and --print-duration need --scenario");
    return 2;
  }

  std::optional<stewart::Scenario> scenario;
  if (!scenario_name.empty()) {
    try {
      scenario = stewart::LoadScenario(stewart::ResolveScenarioPath(scenario_name));
    } catch (const stewart::ConfigError& e) {
      spdlog::error("bad scenario: {}", e.what());
      return 2;
    }
    if (print_duration) {
      std::cout << scenario->duration_s() << std::endl;
      return 0;
    }
  }

  const stewart::StackConfig config = stewart::LoadNodeConfigOrExit(node_options);

  stewart::PrepareForRealTimeIfScheduled("controller");
  if (scenario) {
    if (auto t = stewart::FirstTimeOutsideWorkspace(*scenario, config.platform)) {
      spdlog::warn(
          "scenario '{}' leaves the workspace at t = {} s: those setpoints will be "
          "rejected and the last valid one held",
          scenario->name(), *t);
    }
  }
  try {
    stewart::ControllerNode node(config, std::move(scenario), exit_at_end);
    return node.Run();
  } catch (const std::exception& e) {
    spdlog::error("controller: {}", e.what());
    return 1;
  }
}
