// The real stack over LCM, as tools/launch.sh starts it: plant_sim in
// lockstep, estimator, controller and safety as separate processes, recorded
// by lcm-logger, on a private URL. A short stretch of each scenario; every
// configured position and velocity limit must hold on the recorded ground
// truth (STATE_TRUE) within the tolerance docs/safety.md states (1 mm,
// 1 mm/s), and the run must have challenged the limits.
//
// What a failure looks like: a limit exceeded by more than the tolerance
// fails naming the limit, the excess, the time and the value; a process that
// dies or a stack that does not come up makes the launcher exit 1 (124 after
// the timeout guard), reported with the launcher's output. The temporary run
// folder (log.lcm, config.yaml, run.yaml, <process>.log) is then kept and its
// path printed; after a pass it is removed.
#include <gtest/gtest.h>
#include <stdlib.h>
#include <sys/wait.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <lcm/lcm-cpp.hpp>
#include <limits>
#include <optional>
#include <ostream>
#include <sstream>
#include <string>
#include <vector>

#include "stewart/config/config_loader.h"
#include "stewart/state_t.hpp"

namespace stewart {
namespace {

constexpr double kLimitTolerance = 1e-3;  // m and m/s, docs/safety.md "Tolerance"
constexpr int kLaunchTimeoutS = 300;      // guard on each launcher run (SIGTERM, then SIGKILL)
constexpr const char* kAxisNames[6] = {"x", "y", "z", "phi", "theta", "psi"};

struct StackCase {
  const char* scenario;
  int lcm_port;       // this file's private ports: 7820-7829
  double duration_s;  // simulated seconds
  double min_max_x;   // the platform must reach this x (m): the run challenged the limits
};

// paper: x moves to 0.1 m at the 0.015 m/s velocity limit during 0-10 s, then
// y starts. beyond-limits: x steps to 0.14 m, beyond the 0.11 m limit.
const StackCase kCases[] = {{"paper", 7820, 12.0, 0.09}, {"beyond-limits", 7821, 12.0, 0.10}};

void PrintTo(const StackCase& c, std::ostream* os) {
  *os << c.scenario << " (" << c.duration_s << " s, LCM port " << c.lcm_port << ")";
}

std::string ShellQuote(const std::string& s) {
  std::string quoted = "'";
  for (char ch : s) {
    if (ch == '\'') {
      quoted += "'\\''";
    } else {
      quoted += ch;
    }
  }
  return quoted + "'";
}

std::string ReadFile(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

std::string Format(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", value);
  return text;
}

/// Runs tools/launch.sh on the build folder this test was built in; its
/// output goes to `output_path`. Returns the exit code (128 + signal if
/// killed, -1 if the shell could not start). `--no-build`: the test runs the
/// programs as built (ctest must not rebuild under itself); one launcher at a
/// time per build folder (flock), so parallel ctest runs do not share 2 cores
/// four processes each.
int RunLauncher(const StackCase& c, const std::string& run_dir, const std::string& output_path) {
  const std::string url = "udpm://239.255.76.67:" + std::to_string(c.lcm_port) + "?ttl=0";
  const std::string command =
      "cd " + ShellQuote(STEWART_SOURCE_DIR) +
      " && STEWART_BUILD_DIR=" + ShellQuote(STEWART_BUILD_DIR) + " flock " +
      ShellQuote(std::string(STEWART_BUILD_DIR) + "/stack_launch.lock") + " timeout -k 30 " +
      std::to_string(kLaunchTimeoutS) + " tools/launch.sh --scenario " + ShellQuote(c.scenario) +
      " --duration " + Format(c.duration_s) + " --no-build --no-report --out " +
      ShellQuote(run_dir) + " --lcm-url " + ShellQuote(url) + " >" + ShellQuote(output_path) +
      " 2>&1";
  const int status = std::system(command.c_str());
  if (status == -1) return -1;
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  return WIFSIGNALED(status) ? 128 + WTERMSIG(status) : -1;
}

/// One side of one configured limit: excess = sign * (value - bound), > 0 outside.
struct Bound {
  std::string name;
  bool velocity = false;
  int axis = 0;
  double sign = 1.0;
  double bound = 0.0;
  double max_excess = -std::numeric_limits<double>::infinity();
  double at_s = 0.0;
  double value_at_max = 0.0;
};

std::vector<Bound> BoundsOf(const SafetyConfig& safety) {
  std::vector<Bound> bounds;
  auto add = [&bounds](const std::string& kind, bool velocity, int axis,
                       const std::optional<double>& lower, const std::optional<double>& upper) {
    const std::string prefix = kind + " " + kAxisNames[axis];
    if (upper) bounds.push_back({prefix + " <= " + Format(*upper), velocity, axis, 1.0, *upper});
    if (lower) bounds.push_back({prefix + " >= " + Format(*lower), velocity, axis, -1.0, *lower});
  };
  for (const PositionLimitConfig& p : safety.position_limits) {
    add("position", false, p.axis, p.lower, p.upper);
  }
  for (const VelocityLimitConfig& v : safety.velocity_limits) {
    add("velocity", true, v.axis, v.lower, v.upper);
  }
  return bounds;
}

struct TruthSummary {
  state_t first{};  // the first ground-truth sample
  long samples = 0;
  long undecodable = 0;
  long non_finite = 0;
  double last_s = 0.0;  // time of the last sample after the first
  double max_x = -std::numeric_limits<double>::infinity();
  double max_xd = -std::numeric_limits<double>::infinity();
  std::vector<Bound> bounds;
  const Bound* Worst() const {
    const Bound* worst = nullptr;
    for (const Bound& b : bounds) {
      if (worst == nullptr || b.max_excess > worst->max_excess) worst = &b;
    }
    return worst;
  }
};

/// Every ground-truth message of the log, checked against every bound.
TruthSummary ReadGroundTruth(const std::string& log_path, const StackConfig& config) {
  TruthSummary s;
  s.bounds = BoundsOf(config.safety);
  lcm::LogFile log(log_path, "r");
  if (!log.good()) return s;
  int64_t first_utime = -1;
  while (const lcm::LogEvent* event = log.readNextEvent()) {
    if (event->channel != config.lcm.channels.state_truth) continue;
    state_t truth{};
    if (truth.decode(event->data, 0, event->datalen) != event->datalen) {
      ++s.undecodable;
      continue;
    }
    bool finite = true;
    for (int i = 0; i < 6; ++i) {
      finite = finite && std::isfinite(truth.q[i]) && std::isfinite(truth.qd[i]);
    }
    if (!finite) {
      ++s.non_finite;
      continue;
    }
    if (first_utime < 0) first_utime = truth.utime;
    const double t_s = static_cast<double>(truth.utime - first_utime) * 1e-6;
    if (s.samples == 0) s.first = truth;
    s.last_s = t_s;
    ++s.samples;
    s.max_x = std::max(s.max_x, truth.q[0]);
    s.max_xd = std::max(s.max_xd, truth.qd[0]);
    for (Bound& b : s.bounds) {
      const double value = b.velocity ? truth.qd[b.axis] : truth.q[b.axis];
      const double excess = b.sign * (value - b.bound);
      if (excess > b.max_excess) {
        b.max_excess = excess;
        b.at_s = t_s;
        b.value_at_max = value;
      }
    }
  }
  return s;
}

class StackLockstep : public ::testing::TestWithParam<StackCase> {
 protected:
  void SetUp() override {
    char dir[] = "/tmp/stewart_stack_test_XXXXXX";
    ASSERT_NE(mkdtemp(dir), nullptr) << std::strerror(errno);
    root_ = dir;
  }
  void TearDown() override {
    if (root_.empty()) return;
    if (HasFailure()) {
      std::printf("run folder kept: %s\n", root_.c_str());
      return;
    }
    std::error_code ignored;
    std::filesystem::remove_all(root_, ignored);
  }

  std::string root_;
};

TEST_P(StackLockstep, LimitsHoldOnGroundTruth) {
  const StackCase& c = GetParam();
  const std::string run_dir = root_ + "/run";
  const std::string output_path = root_ + "/launch.out";
  const auto start = std::chrono::steady_clock::now();
  const int exit_code = RunLauncher(c, run_dir, output_path);
  const double wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_EQ(exit_code, 0) << "tools/launch.sh failed after " << wall_s << " s (124: killed by the "
                          << kLaunchTimeoutS << " s guard); its output:\n"
                          << ReadFile(output_path);

  // The limits the run used: the launcher keeps its config beside the log.
  const StackConfig config = LoadStackConfig(run_dir + "/config.yaml");
  ASSERT_FALSE(config.safety.position_limits.empty());
  ASSERT_FALSE(config.safety.velocity_limits.empty());
  const TruthSummary s = ReadGroundTruth(run_dir + "/log.lcm", config);
  const Bound* worst = s.Worst();
  ASSERT_NE(worst, nullptr);
  std::printf(
      "[stack] %s: %g s simulated, launcher %.1f s, %ld truth samples, max x %.5f m, "
      "max xd %.5f m/s, max excess %.2e (%s)\n",
      c.scenario, c.duration_s, wall_s, s.samples, s.max_x, s.max_xd, worst->max_excess,
      worst->name.c_str());

  // The run was meaningful: a whole recording, and the platform went where
  // the limits are.
  EXPECT_EQ(s.undecodable, 0);
  EXPECT_EQ(s.non_finite, 0);
  EXPECT_GE(static_cast<double>(s.samples), 0.95 * c.duration_s * config.sensors.rate_hz)
      << "ground truth on " << config.lcm.channels.state_truth << ": " << s.last_s << " s from seq "
      << s.first.seq;
  EXPECT_GE(s.max_x, c.min_max_x);
  // The log decodes to what the plant published: it starts at rest at the
  // configured initial pose (catches a broken decode, see CMakeLists.txt;
  // 0.1 mm allows for a first sample or two the logger missed).
  for (int i = 0; i < 6; ++i) {
    EXPECT_NEAR(s.first.q[i], config.plant_sim.initial_pose(i), 1e-4) << kAxisNames[i];
  }

  for (const Bound& b : s.bounds) {
    EXPECT_LE(b.max_excess, kLimitTolerance)
        << b.name << " exceeded by " << b.max_excess << " at t = " << b.at_s << " s (value "
        << b.value_at_max << ")";
  }
}

INSTANTIATE_TEST_SUITE_P(Scenarios, StackLockstep, ::testing::ValuesIn(kCases),
                         [](const ::testing::TestParamInfo<StackCase>& param_info) {
                           std::string name = param_info.param.scenario;
                           for (char& ch : name)
                             if (ch == '-') ch = '_';
                           return name;
                         });

}  // namespace
}  // namespace stewart
