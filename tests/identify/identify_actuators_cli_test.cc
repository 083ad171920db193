// stewart_identify --mode actuators end to end (docs/hardware.md, "Identify
// the actuators"): in simulation (in process), through hw_bridge --bringup
// and hw_emulator over LCM (processes the tool starts; LCM port 7860,
// device UDP ports 17760/17761), and its answers to bad input and to a
// guard trip. tests/identify owns LCM ports 7850-7859 (payload) and
// 7860-7869 (actuators).
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "stewart/config/config_loader.h"
#include "stewart/config/default_config.h"
#include "stewart/node/lcm_handle.h"
#include "stewart/test_support/stack_launch.h"

namespace stewart::test {
namespace {

constexpr int kHwLcmPort = 7860;
constexpr int kNoBridgeLcmPort = 7861;
constexpr int kDevicePort = 17760;
constexpr int kBridgePort = 17761;

// The motors of the plant: the config's P-16P values +20 % or -25 %.
constexpr double kStallForceN = 180.0;
constexpr double kNoLoadSpeedMps = 0.015;
constexpr double kReflectedMassKg = 96.0;
constexpr double kDeadBandDuty = 0.096;
constexpr const char* kMotorTruth = R"(
actuators:
  model: dc_motor
  motor: {stall_force_n: 180, no_load_speed_mps: 0.015, reflected_mass_kg: 96,
          dead_band_duty: 0.096, coulomb_friction_n: 1.5}
)";

class IdentifyActuatorsCli : public WithRunFolder<::testing::Test> {
 protected:
  IdentifyActuatorsCli() : WithRunFolder("stewart_identify_actuators_test") {}

  // stewart_identify with `args` and the P-16P overlay, its output in
  // <run folder>/identify.out.
  int Identify(const std::string& args, bool lock = false) {
    const std::string guard =
        lock ? "flock " + ShellQuote(std::string(STEWART_BUILD_DIR) + "/stack_launch.lock") + " "
             : "";
    return Shell("cd " + ShellQuote(STEWART_SOURCE_DIR) + " && " + guard + "timeout -k 10 120 " +
                 ShellQuote(IDENTIFY_PATH) + " --mode actuators " + args + " >" +
                 ShellQuote(Output()) + " 2>&1");
  }
  std::string Output() const { return run_folder_ + "/identify.out"; }
  std::string P16p() const { return "--overlay " + ShellQuote(DcMotorOverlayPath()) + " "; }
  std::string Truth(const std::string& text) {
    const std::string path = run_folder_ + "/truth.yaml";
    std::ofstream(path) << text;
    return path;
  }

  // The overlay: only actuators.motor's four keys, with uncertainties; it
  // applies after the P-16P overlay. Returns the motor values it gives.
  DcMotorParams ReadOverlay(const std::string& path) {
    const YAML::Node overlay = YAML::LoadFile(path);
    EXPECT_EQ(overlay.size(), 1u);
    EXPECT_EQ(overlay["actuators"].size(), 1u);
    EXPECT_EQ(overlay["actuators"]["motor"].size(), 4u);
    EXPECT_NE(ReadFile(path).find("+-"), std::string::npos);
    return LoadStackConfig(DefaultConfigPath(), {DcMotorOverlayPath(), path}).actuators.motor;
  }
};

void ExpectWithin(const DcMotorParams& m, double tolerance) {
  std::printf("identified: stall %.2f N, no-load %.5f m/s, rotor %.2f kg, dead band %.4f\n",
              m.stall_force_n, m.no_load_speed_mps, m.reflected_mass_kg, m.dead_band_duty);
  EXPECT_NEAR(m.stall_force_n, kStallForceN, tolerance * kStallForceN);
  EXPECT_NEAR(m.no_load_speed_mps, kNoLoadSpeedMps, tolerance * kNoLoadSpeedMps);
  EXPECT_NEAR(m.reflected_mass_kg, kReflectedMassKg, tolerance * kReflectedMassKg);
  EXPECT_NEAR(m.dead_band_duty, kDeadBandDuty, tolerance * kDeadBandDuty);
}

TEST_F(IdentifyActuatorsCli, RecoversOtherMotorsInSimulation) {
  const std::string out = run_folder_ + "/motors.yaml";
  ASSERT_EQ(Identify(P16p() + "--plant sim --truth " + ShellQuote(Truth(kMotorTruth)) + " --out " +
                     ShellQuote(out)),
            0)
      << ReadFile(Output());
  ExpectWithin(ReadOverlay(out), 0.05);
  EXPECT_NE(ReadFile(Output()).find("actuators:"), std::string::npos);  // printed too
}

// Over LCM: the tool starts hw_emulator (the truth's motors, the device's
// ADC alone: docs/hardware.md) and hw_bridge --bringup, drives one leg in
// real time (~17 s) and stops them. One leg, so a looser bound.
TEST_F(IdentifyActuatorsCli, ThroughHwBridgeBringupAndTheEmulatorOverLcm) {
  const std::string truth = Truth(std::string(kMotorTruth) + "sensors: {leg_adc_bits: 0}\n");
  const std::string out = run_folder_ + "/motors.yaml";
  const std::string run_dir = run_folder_ + "/run";
  ASSERT_EQ(Identify(P16p() + "--plant hw --device-emulator --truth " + ShellQuote(truth) +
                         " --legs 3 --lcm-url " + ShellQuote(PrivateLcmUrl(kHwLcmPort)) +
                         " --device-port " + std::to_string(kDevicePort) + " --local-port " +
                         std::to_string(kBridgePort) + " --run-dir " + ShellQuote(run_dir) +
                         " --out " + ShellQuote(out),
                     true),
            0)
      << ReadFile(Output()) << ReadFile(run_dir + "/hw_bridge.log");
  ExpectWithin(ReadOverlay(out), 0.12);
  const std::string bridge_log = ReadFile(run_dir + "/hw_bridge.log");
  EXPECT_NE(bridge_log.find("BRING-UP MODE"), std::string::npos) << bridge_log;
  EXPECT_NE(ReadFile(run_dir + "/hw_emulator.log").find("physics from truth"), std::string::npos);
  EXPECT_NE(ReadFile(Output()).find("via hw_bridge --bringup"), std::string::npos);
}

TEST_F(IdentifyActuatorsCli, BadInputGivesOneClearError) {
  const std::string out = " --out " + ShellQuote(run_folder_ + "/never.yaml");
  // The shipped config's legs are ideal force sources.
  EXPECT_EQ(Identify("--plant sim" + out), 2);
  EXPECT_NE(ReadFile(Output()).find("config/overlays/p16p.yaml"), std::string::npos)
      << ReadFile(Output());
  EXPECT_EQ(Identify(P16p() + "--plant sim --device-emulator" + out), 2);
  EXPECT_NE(ReadFile(Output()).find("goes with --plant hw"), std::string::npos)
      << ReadFile(Output());
  EXPECT_EQ(Identify(P16p() + "--plant hw --truth " + ShellQuote(Truth(kMotorTruth)) + out), 2);
  EXPECT_NE(ReadFile(Output()).find("--truth"), std::string::npos) << ReadFile(Output());
  EXPECT_EQ(Identify(P16p() + "--plant sim --legs 1,9" + out), 2);
  // A truth whose legs are not DC motors.
  EXPECT_EQ(Identify(P16p() + "--plant sim --truth " +
                     ShellQuote(Truth("actuators: {model: ideal_force}\n")) + out),
            2);
  EXPECT_NE(ReadFile(Output()).find("not DC motors"), std::string::npos) << ReadFile(Output());
  // No bridge on the URL.
  EXPECT_EQ(Identify(P16p() + "--plant hw --bridge-running --sample-timeout 0.5 --lcm-url " +
                     ShellQuote(PrivateLcmUrl(kNoBridgeLcmPort)) + out),
            2);
  EXPECT_NE(ReadFile(Output()).find("no sensor_t from hw_bridge"), std::string::npos)
      << ReadFile(Output());
  EXPECT_FALSE(std::filesystem::exists(run_folder_ + "/never.yaml"));
}

// Motors four times as fast as the config's: the direction check's duty
// takes the leg past the guard's cap (twice the config motor's full-duty
// speed); the tool stops, says why, exits 1 and writes nothing.
TEST_F(IdentifyActuatorsCli, AGuardTripStopsTheRunAndWritesNothing) {
  const std::string out = run_folder_ + "/never.yaml";
  const std::string fast = "actuators:\n  model: dc_motor\n  motor: {no_load_speed_mps: 0.08}\n";
  EXPECT_EQ(Identify(P16p() + "--plant sim --truth " + ShellQuote(Truth(fast)) + " --out " +
                     ShellQuote(out)),
            1);
  EXPECT_NE(ReadFile(Output()).find("guard: leg 0 speed_cap"), std::string::npos)
      << ReadFile(Output());
  EXPECT_FALSE(std::filesystem::exists(out));
}

}  // namespace
}  // namespace stewart::test
