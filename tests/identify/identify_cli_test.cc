// stewart_identify end to end: the excitation run over LCM (tools/launch.sh,
// plant_sim in lockstep with a payload truth, the real estimator, controller
// and safety processes), the fit on the recorded estimate, the overlay; then
// the overlay with tools/launch.sh --overlay; and the tool's answers to bad
// input (one line, exit 2).
//
// The stack runs with the payload's mass and CoM as a rough prior (--overlay,
// as if weighed and placed by hand), or with none: it estimates the payload
// as part of the model error d. A stack that does not estimate d cannot carry
// the payload: the platform sinks onto its end stops and the tool refuses the
// run (AnUnknownPayloadSinksOntoTheEndStopsWithoutTheModelError). The
// inertia stays the config's; the fit never reads the prior (identify_test:
// FitIgnoresThePlatformBodyOfTheModel).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <lcm/lcm-cpp.hpp>
#include <map>
#include <string>

#include "stewart/config/config_loader.h"
#include "stewart/config/truth_loader.h"
#include "stewart/node/lcm_handle.h"
#include "stewart/test_support/stack_launch.h"

namespace stewart::test {
namespace {

constexpr int kLcmPort = 7850;  // tests/identify owns 7850-7859
constexpr int kOverlayLcmPort = 7851;
constexpr int kNoPriorLcmPort = 7852;

// The payload the brief names: 0.25 kg at (0.05, -0.03, 0.02) m in {P}.
constexpr const char* kPayloadTruth = R"(
platform:
  payload: {mass_kg: 0.25, position_m: [0.05, -0.03, 0.02]}
)";

class IdentifyCli : public WithRunFolder<::testing::Test> {
 protected:
  IdentifyCli() : WithRunFolder("stewart_identify_test") {}

  // stewart_identify with `args`, its output in <run folder>/identify.out,
  // serialised with the other stack launches of this build folder.
  int Identify(const std::string& args) {
    return Shell("cd " + ShellQuote(STEWART_SOURCE_DIR) +
                 " && STEWART_BUILD_DIR=" + ShellQuote(STEWART_BUILD_DIR) + " flock " +
                 ShellQuote(std::string(STEWART_BUILD_DIR) + "/stack_launch.lock") +
                 " timeout -k 30 " + std::to_string(kLaunchTimeoutS) + " " +
                 ShellQuote(IDENTIFY_PATH) + " " + args + " >" + ShellQuote(Output()) + " 2>&1");
  }
  std::string Output() const { return run_folder_ + "/identify.out"; }
};

// The prior the stack runs with: the payload as weighed and placed by hand,
// 1 g heavy and 5 mm off in x and y (CoM 2 mm, 11 %, off the plant's), the
// bare plate's inertia (9 % off).
std::string WritePrior(const std::string& path) {
  Payload measured;
  measured.mass_kg = 0.251;
  measured.position_in_P_m = Vector3d(0.055, -0.025, 0.02);
  const PlatformParams prior = WithPayload(LoadStackConfig(DefaultConfigPath()).platform, measured);
  const Vector3d& c = prior.platform_com_in_P_m;
  char text[256];
  std::snprintf(text, sizeof text, "platform: {mass_kg: %.17g, com_m: [%.17g, %.17g, %.17g]}\n",
                prior.platform_mass_kg, c.x(), c.y(), c.z());
  std::ofstream(path) << text;
  return path;
}

TEST_F(IdentifyCli, RecoversAPayloadInSimulation) {
  const std::string truth_path = run_folder_ + "/payload.yaml";
  std::ofstream(truth_path) << kPayloadTruth;
  const StackConfig config = LoadStackConfig(DefaultConfigPath());
  // The plant the run simulates: the config's platform with the payload.
  const PlatformParams truth = LoadPlantTruth(config, truth_path).platform;
  const std::string prior_path = WritePrior(run_folder_ + "/prior.yaml");
  const std::string overlay_path = run_folder_ + "/identified.yaml";
  const std::string run_dir = run_folder_ + "/run";
  const int code = Identify(
      "--mode payload --plant sim --truth " + ShellQuote(truth_path) + " --overlay " +
      ShellQuote(prior_path) + " --seed 7 --run-dir " + ShellQuote(run_dir) + " --lcm-url " +
      ShellQuote(PrivateLcmUrl(kLcmPort)) + " --out " + ShellQuote(overlay_path));
  ASSERT_EQ(code, 0) << ReadFile(Output());

  // The overlay holds only the identified keys, with their uncertainty.
  const YAML::Node overlay = YAML::LoadFile(overlay_path);
  ASSERT_TRUE(overlay.IsMap());
  EXPECT_EQ(overlay.size(), 1u);
  EXPECT_EQ(overlay["platform"].size(), 4u);
  const std::string text = ReadFile(overlay_path);
  EXPECT_NE(text.find("+-"), std::string::npos);
  EXPECT_NE(text.find("residual"), std::string::npos);

  const StackConfig identified = LoadStackConfig(DefaultConfigPath(), {overlay_path});
  const PlatformParams& p = identified.platform;
  const double mass_error =
      std::abs(p.platform_mass_kg - truth.platform_mass_kg) / truth.platform_mass_kg;
  const double com_error =
      (p.platform_com_in_P_m - truth.platform_com_in_P_m).norm() / truth.platform_com_in_P_m.norm();
  const double inertia_error =
      (PlatformInertiaInP(p) - PlatformInertiaInP(truth)).norm() / PlatformInertiaInP(truth).norm();
  std::printf(
      "identified: mass %.4f kg (true %.4f, %.3f %%), CoM error %.3f %%, inertia error "
      "%.3f %% (prior's inertia error %.1f %%)\n",
      p.platform_mass_kg, truth.platform_mass_kg, 100 * mass_error, 100 * com_error,
      100 * inertia_error,
      100 * (PlatformInertiaInP(config.platform) - PlatformInertiaInP(truth)).norm() /
          PlatformInertiaInP(truth).norm());
  EXPECT_LT(mass_error, 0.02);
  EXPECT_LT(com_error, 0.05);
  EXPECT_LT(inertia_error, 0.05);

  // The run folder's config.yaml is what ran: the identification overlay
  // (the dynamics estimator with d) and the prior merged in.
  const StackConfig ran = LoadStackConfig(run_dir + "/config.yaml");
  EXPECT_EQ(ran.estimator.process_model, EstimatorProcessModel::kDynamics);
  EXPECT_TRUE(ran.estimator.estimate_disturbance);
  EXPECT_EQ(ran.platform.platform_mass_kg,
            YAML::LoadFile(prior_path)["platform"]["mass_kg"].as<double>());
  EXPECT_EQ(ran.platform.platform_inertia_kgm2, config.platform.platform_inertia_kgm2);
}

// No prior at all: the stack carries the unknown payload (estimated as part
// of d) and the fit recovers it within the same bounds.
TEST_F(IdentifyCli, RecoversAnUnknownPayloadWithoutAPrior) {
  const std::string truth_path = run_folder_ + "/payload.yaml";
  std::ofstream(truth_path) << kPayloadTruth;
  const StackConfig config = LoadStackConfig(DefaultConfigPath());
  const PlatformParams truth = LoadPlantTruth(config, truth_path).platform;
  const std::string overlay_path = run_folder_ + "/identified.yaml";
  const int code = Identify("--mode payload --plant sim --truth " + ShellQuote(truth_path) +
                            " --seed 3 --run-dir " + ShellQuote(run_folder_ + "/run") +
                            " --lcm-url " + ShellQuote(PrivateLcmUrl(kNoPriorLcmPort + 1)) +
                            " --out " + ShellQuote(overlay_path));
  ASSERT_EQ(code, 0) << ReadFile(Output());
  const PlatformParams p = LoadStackConfig(DefaultConfigPath(), {overlay_path}).platform;
  EXPECT_LT(std::abs(p.platform_mass_kg - truth.platform_mass_kg) / truth.platform_mass_kg, 0.02);
  EXPECT_LT(
      (p.platform_com_in_P_m - truth.platform_com_in_P_m).norm() / truth.platform_com_in_P_m.norm(),
      0.05);
  EXPECT_LT(
      (PlatformInertiaInP(p) - PlatformInertiaInP(truth)).norm() / PlatformInertiaInP(truth).norm(),
      0.05);
}

TEST_F(IdentifyCli, AnUnknownPayloadSinksOntoTheEndStopsWithoutTheModelError) {
  // Without the prior and without estimating d, the stack's model is 0.25 kg
  // too light: the filter holds the commanded lift to what the model needs
  // and the platform sinks onto its end stops, where the model does not
  // hold. The tool says so.
  const std::string truth_path = run_folder_ + "/payload.yaml";
  std::ofstream(truth_path) << kPayloadTruth;
  const std::string no_d_path = run_folder_ + "/no_d.yaml";
  std::ofstream(no_d_path)
      << "estimator: {disturbance: {enabled: false}}\n"
      << "controller: {compensate_disturbance: false}\n"
      << "safety: {use_disturbance_estimate: false, velocity_rate_per_s: 1.0}\n"
      // plant_sim's own guard holds a sinking platform 5 mm before its stops
      // (docs/operations.md, "The actuator guard"); this test is about the
      // tool refusing a run that sat on them, so the guard lets it get there.
      << "guard: {leg_stroke_margin_m: 0.0}\n";
  const int code = Identify("--mode payload --plant sim --truth " + ShellQuote(truth_path) +
                            " --overlay " + ShellQuote(no_d_path) + " --duration 8 --run-dir " +
                            ShellQuote(run_folder_ + "/run") + " --lcm-url " +
                            ShellQuote(PrivateLcmUrl(kNoPriorLcmPort)) + " --out " +
                            ShellQuote(run_folder_ + "/identified.yaml"));
  EXPECT_EQ(code, 2);
  EXPECT_NE(ReadFile(Output()).find("at a stroke end"), std::string::npos) << ReadFile(Output());
  EXPECT_FALSE(std::ifstream(run_folder_ + "/identified.yaml").good());
}

TEST_F(IdentifyCli, TheLauncherRunsTheStackWithAnOverlay) {
  // The channel suffix shows which config each process loaded: every
  // message of the run must be on a suffixed channel.
  const std::string overlay_path = run_folder_ + "/heavier.yaml";
  std::ofstream(overlay_path) << "platform: {mass_kg: 0.87, com_m: [0.014, -0.009, 0.009]}\n"
                                 "lcm: {channel_suffix: _OV}\n";
  const std::string run_dir = run_folder_ + "/run";
  const LaunchResult launch = RunLauncher(
      "--scenario paper --duration 1 --no-build --no-report --overlay " + ShellQuote(overlay_path),
      kOverlayLcmPort, run_dir, run_folder_ + "/launch.out");
  ASSERT_EQ(launch.exit_code, 0) << LaunchFailure(launch);
  const StackConfig ran = LoadStackConfig(run_dir + "/config.yaml");
  EXPECT_EQ(ran.platform.platform_mass_kg, 0.87);
  EXPECT_EQ(ran.platform.platform_com_in_P_m.x(), 0.014);
  EXPECT_EQ(ran.lcm.channels.state_estimate, "STEWART_STATE_EST_OV");
  EXPECT_NE(ReadFile(run_dir + "/run.yaml").find("overlays: [" + overlay_path + "]"),
            std::string::npos);
  std::map<std::string, long> messages;
  lcm::LogFile log(run_dir + "/log.lcm", "r");
  ASSERT_TRUE(log.good());
  while (const lcm::LogEvent* e = log.readNextEvent()) ++messages[e->channel];
  for (const char* channel : {"STEWART_SENSORS_OV", "STEWART_STATE_EST_OV",
                              "STEWART_CMD_NOMINAL_OV", "STEWART_CMD_SAFE_OV"}) {
    EXPECT_GT(messages[channel], 500) << channel;
  }
  for (const auto& [channel, count] : messages) {
    EXPECT_EQ(channel.substr(channel.size() - 3), "_OV") << channel << ": " << count;
  }
}

TEST_F(IdentifyCli, TheLauncherRejectsAnOverlayWithAnUnknownKey) {
  const std::string overlay_path = run_folder_ + "/typo.yaml";
  std::ofstream(overlay_path) << "platform: {mass_kgg: 0.87}\n";
  const LaunchResult launch =
      RunLauncher("--no-build --no-report --overlay " + ShellQuote(overlay_path), kOverlayLcmPort,
                  run_folder_ + "/run", run_folder_ + "/launch.out");
  EXPECT_EQ(launch.exit_code, 2);
  EXPECT_NE(ReadFile(launch.output_path).find("platform.mass_kgg"), std::string::npos)
      << ReadFile(launch.output_path);
}

TEST_F(IdentifyCli, BadInputGivesOneClearError) {
  const std::string out = " --out " + ShellQuote(run_folder_ + "/never.yaml");
  // A log that is not an LCM log.
  const std::string not_a_log = run_folder_ + "/not_a_log.lcm";
  std::ofstream(not_a_log) << "hello\n";
  EXPECT_EQ(Identify("--mode payload --log " + ShellQuote(not_a_log) + out), 2);
  EXPECT_NE(ReadFile(Output()).find("no state_t message"), std::string::npos) << ReadFile(Output());
  // A log without the channels: an empty file.
  const std::string empty_log = run_folder_ + "/empty.lcm";
  std::ofstream(empty_log).flush();
  EXPECT_EQ(Identify("--mode payload --log " + ShellQuote(empty_log) + out), 2);
  EXPECT_NE(ReadFile(Output()).find("identification:"), std::string::npos) << ReadFile(Output());
  // No mode, an unknown mode, a missing log.
  EXPECT_EQ(Identify(out), 2) << ReadFile(Output());
  EXPECT_NE(ReadFile(Output()).find("--mode is required"), std::string::npos) << ReadFile(Output());
  EXPECT_EQ(Identify("--mode mass" + out), 2);
  EXPECT_EQ(Identify("--mode payload --log /nonexistent.lcm" + out), 2);
  EXPECT_NE(ReadFile(Output()).find("/nonexistent.lcm"), std::string::npos) << ReadFile(Output());
  EXPECT_FALSE(std::ifstream(run_folder_ + "/never.yaml").good());
}

}  // namespace
}  // namespace stewart::test
