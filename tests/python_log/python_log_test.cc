// The Python log reader (tools/python/stewart_log) on a real run:
// tools/launch.sh runs the LCM stack (plant_sim in lockstep, estimator,
// controller, safety, stewart_logger) on the paper scenario for 2 s on a
// private URL; stewart_log_export writes the log's CSVs; compare_with_csv.py
// asserts that each CSV equals the reader's table of its channel: the same
// rows, every column, the values exactly (tests/python_log/compare_with_csv.py
// says how text, health's counters and padded barrier columns are matched).
// Every channel the stack publishes in simulation is required (the operator's
// is empty without an operator).
//
// On a failure the temporary run folder is kept and its path printed.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "stewart/config/config_loader.h"
#include "stewart/test_support/stack_launch.h"

namespace stewart::test {
namespace {

constexpr int kLcmPort = 7960;  // this folder's ports: 7960-7969
constexpr double kDurationS = 2.0;

class PythonLog : public WithRunFolder<::testing::Test> {
 protected:
  PythonLog() : WithRunFolder("stewart_python_log") {}

  /// Runs `command` with its output to <run folder>/<name>.out: exit code and output.
  std::pair<int, std::string> Run(const std::string& command, const std::string& name) {
    const std::string out = run_folder_ + "/" + name + ".out";
    const int code = Shell(command + " >" + ShellQuote(out) + " 2>&1");
    return {code, ReadFile(out)};
  }
};

TEST_F(PythonLog, TablesEqualTheExportedCsv) {
  const std::string run = run_folder_ + "/run";
  const LaunchResult launch =
      RunLauncher("--no-build --no-report --scenario paper --duration " + FormatNumber(kDurationS),
                  kLcmPort, run, run_folder_ + "/launch.out");
  ASSERT_EQ(launch.exit_code, 0) << LaunchFailure(launch);

  const std::string log = run + "/log.lcm";
  const std::string csv = run_folder_ + "/csv";
  const auto [export_code, export_output] =
      Run(ShellQuote(STEWART_LOG_EXPORT_PATH) + " " + ShellQuote(log) + " --out " + ShellQuote(csv),
          "export");
  ASSERT_EQ(export_code, 0) << export_output;

  const ChannelNames ch = LoadStackConfig(run + "/config.yaml").lcm.channels;
  std::string require;
  for (const std::string& channel :
       {ch.sensors, ch.state_estimate, ch.state_truth, ch.command_nominal, ch.command_safe,
        ch.setpoint, ch.safety_diagnostics, ch.health, ch.supervisor}) {
    require += " --require " + ShellQuote(channel);
  }
  const auto [code, output] =
      Run("PYTHONDONTWRITEBYTECODE=1 PYTHONPATH=" + ShellQuote(STEWART_PYTHONPATH) + " " +
              ShellQuote(STEWART_PYTHON3) + " " + ShellQuote(STEWART_COMPARE_SCRIPT) + " " +
              ShellQuote(log) + " " + ShellQuote(csv) + require,
          "compare");
  std::printf("%s", output.c_str());
  EXPECT_EQ(code, 0) << output;
}

}  // namespace
}  // namespace stewart::test
