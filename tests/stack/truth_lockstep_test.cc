// The same truth and seed, in process (stewart_campaign's loop) and over LCM
// (tools/launch.sh --truth --seed, plant_sim in lockstep with the real
// estimator, controller and safety processes), give the same ground-truth
// trajectory: what the campaign measures is what the stack does.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <lcm/lcm-cpp.hpp>
#include <map>
#include <sstream>
#include <string>

#include "stewart/config/config_loader.h"
#include "stewart/config/scenario_loader.h"
#include "stewart/config/truth_loader.h"
#include "stewart/stack/closed_loop.h"
#include "stewart/state_t.hpp"
#include "stewart/test_support/stack_launch.h"

namespace stewart {
namespace {

using test::RunLauncher;
using test::ShellQuote;

constexpr int kLcmPort = 7826;  // tests/stack owns 7820-7829
constexpr double kDurationS = 1.5;
constexpr double kTailS = 0.1;  // the LCM run goes on this long after the compared ticks
constexpr unsigned kSeed = 5;

// A plant well off the model: heavier, a payload off-centre, more friction,
// a slower actuator, 1.5 ms of latency and a push.
constexpr const char* kTruth = R"(
platform:
  mass_kg: 0.70
  payload: {mass_kg: 0.1, position_m: [0.04, -0.02, 0.02]}
actuators: {viscous_friction_nspm: 3.0, coulomb_friction_n: 0.1, force_gain: [1.05, 0.95, 1, 1, 1.02, 0.98]}
sensors: {leg_scale: 1.002, imu_misalignment_deg: [0.2, -0.1, 0.0]}
latency: {sensor_ms: 0.5, command_ms: 1.0}
disturbance:
  constant_force_n: [0.3, 0.0, -0.2]
  pulses: [{start_s: 1.0, duration_s: 0.2, force_n: [2.0, 1.0, 0.0]}]
)";

class TruthLockstep : public test::WithRunFolder<::testing::Test> {
 protected:
  TruthLockstep() : WithRunFolder("stewart_truth_lockstep") {}
};

TEST_F(TruthLockstep, InProcessAndOverLcmGiveTheSameGroundTruth) {
  const std::string truth_path = run_folder_ + "/truth.yaml";
  std::ofstream(truth_path) << kTruth;
  const StackConfig config = LoadStackConfig(DefaultConfigPath());

  // In process.
  ClosedLoopOptions options;
  options.duration_s = kDurationS;
  options.seed = kSeed;
  options.truth = LoadPlantTruth(config, truth_path);
  std::ostringstream csv;
  csv.precision(17);  // every bit of the trajectory
  const Scenario scenario = LoadScenario(ResolveScenarioPath("paper"));
  const ClosedLoopSummary s = RunClosedLoop(config, scenario, options, &csv);
  ASSERT_TRUE(s.completed) << s.failure;
  std::map<long, Vector6d> in_process;  // tick -> q_true
  {
    std::istringstream lines(csv.str());
    std::string line;
    std::getline(lines, line);  // header
    for (long k = 0; std::getline(lines, line); ++k) {
      std::istringstream fields(line);
      std::string field;
      std::getline(fields, field, ',');  // t
      Vector6d q;
      for (int i = 0; i < 6; ++i) {
        std::getline(fields, field, ',');
        q(i) = std::stod(field);
      }
      in_process[k] = q;
    }
  }

  // Over LCM.
  const std::string run_dir = run_folder_ + "/run";
  const test::LaunchResult launch = RunLauncher(
      // A little longer than the in-process run: how the processes stop at the
      // end of a run (the controller exits when its scenario ends, counted from
      // the first state it received) is not part of the comparison.
      "--scenario paper --duration " + test::FormatNumber(kDurationS + kTailS) + " --truth " +
          ShellQuote(truth_path) + " --seed " + std::to_string(kSeed) + " --no-build --no-report",
      kLcmPort, run_dir, run_folder_ + "/launch.out");
  ASSERT_EQ(launch.exit_code, 0) << test::LaunchFailure(launch);
  lcm::LogFile log(run_dir + "/log.lcm", "r");
  ASSERT_TRUE(log.good());
  long compared = 0;
  double max_difference = 0.0;
  long first_different_tick = -1;
  for (const lcm::LogEvent* e = log.readNextEvent(); e != nullptr; e = log.readNextEvent()) {
    if (e->channel != config.lcm.channels.state_truth) continue;
    state_t truth;
    if (truth.decode(e->data, 0, e->datalen) < 0) continue;
    const auto it = in_process.find(truth.seq);
    if (it == in_process.end()) continue;
    for (int i = 0; i < 6; ++i) {
      const double d = std::abs(truth.q[i] - it->second(i));
      if (d > 0.0 && first_different_tick < 0) {
        first_different_tick = truth.seq;
        std::printf("tick %ld axis %d: LCM %.17g in process %.17g\n", static_cast<long>(truth.seq),
                    i, truth.q[i], it->second(i));
      }
      max_difference = std::max(max_difference, d);
    }
    ++compared;
  }
  // The logger may miss a first sample; the rest is the whole run.
  EXPECT_GE(compared, static_cast<long>(0.95 * kDurationS * config.sensors.rate_hz));
  // Bit for bit: the same classes, the same order, the same numbers.
  EXPECT_EQ(max_difference, 0.0) << "first different at tick " << first_different_tick;
  // And the truth made a difference: the platform did not end where a
  // plant equal to the model ends.
  ClosedLoopOptions exact = options;
  exact.truth.reset();
  const ClosedLoopSummary e = RunClosedLoop(config, scenario, exact, nullptr);
  EXPECT_GT((e.q_final - s.q_final).norm(), 1e-4);
}

}  // namespace
}  // namespace stewart
