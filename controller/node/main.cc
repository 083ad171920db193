// controller: the nominal feedback-linearising PD controller (paper eq. 3)
// as an LCM process. See docs/controller.md.
#include <spdlog/spdlog.h>

#include <iostream>

#include "controller_node.h"
#include "stewart/config/scenario_loader.h"
#include "stewart/node/node_main.h"

int main(int argc, char** argv) {
  std::string scenario_name;
  bool exit_at_end = false;
  bool print_duration = false;
  bool restart_scenario = false;
  std::optional<stewart::Scenario> scenario;
  return stewart::NodeMain(
      argc, argv, {"controller", "Stewart platform nominal controller: state estimate -> F_des"},
      [&](CLI::App& app) {
        app.add_option("-s,--scenario", scenario_name,
                       "scenario name (config/scenarios/<name>.yaml) or path; "
                       "without one, setpoints come live from the setpoint channel");
        app.add_flag("--exit-at-end", exit_at_end, "exit once the scenario's duration has elapsed");
        app.add_flag("--restart-scenario", restart_scenario,
                     "start the scenario over at t = 0 (default: continue at the supervisor's "
                     "motion clock, so a restarted controller takes up where the motion was)");
        app.add_flag("--print-duration", print_duration,
                     "print the scenario's duration in seconds and exit");
      },
      [&](stewart::StackConfig& config) -> std::optional<stewart::ExitCode> {
        STEWART_CHECK_INPUT(!((exit_at_end || print_duration) && scenario_name.empty()),
                            "--exit-at-end/--print-duration", "needs --scenario");
        if (scenario_name.empty()) return std::nullopt;
        scenario = stewart::LoadScenario(stewart::ResolveScenarioPath(scenario_name));
        if (auto t = stewart::FirstTimeOutsideWorkspace(*scenario, config.platform)) {
          spdlog::warn(
              "scenario '{}' leaves the workspace at t = {} s: those setpoints will be "
              "rejected and the last valid one held",
              scenario->name(), *t);
        }
        if (print_duration) {
          std::cout << scenario->duration_s() << std::endl;
          return stewart::ExitCode::kOk;
        }
        return std::nullopt;
      },
      [&](const stewart::StackConfig& config, lcm::LCM* lcm) {
        stewart::ControllerNode node(config, lcm, std::move(scenario), exit_at_end,
                                     restart_scenario);
        return node.Run();
      });
}
