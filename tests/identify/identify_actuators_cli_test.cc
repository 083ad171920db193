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
  int Identify(const std::string& args, bool lock = false, const std::string& mode = "actuators") {
    const std::string guard =
        lock ? "flock " + ShellQuote(std::string(STEWART_BUILD_DIR) + "/stack_launch.lock") + " "
             : "";
    return Shell("cd " + ShellQuote(STEWART_SOURCE_DIR) + " && " + guard + "timeout -k 10 120 " +
                 ShellQuote(IDENTIFY_PATH) + " --mode " + mode + " " + args + " >" +
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

// stewart_identify --mode pots over LCM (docs/hardware.md, "Calibrate the
// pots at the stroke ends"): the tool starts hw_emulator, whose pots read
// with scale and offset errors (up to 1.6 mm at the ends), and hw_bridge
// --bringup --bringup-end-search, takes all six legs to both stroke ends in
// real time (~47 s) and writes the counts there. The counts the emulator's
// pots give at the ends follow from the truth and the config's calibration.
TEST_F(IdentifyActuatorsCli, PotsAtTheStrokeEndsThroughHwBridgeAndTheEmulatorOverLcm) {
  const Vector6d scale = (Vector6d() << 1.003, 0.998, 1.0, 1.002, 0.997, 1.001).finished();
  const Vector6d offset_m = (Vector6d() << -0.001, 0.0008, 0.0015, -0.0005, 0.001, 0.0).finished();
  const std::string truth = Truth(
      "actuators: {model: dc_motor}\n"
      "sensors: {leg_scale: [1.003, 0.998, 1.0, 1.002, 0.997, 1.001],\n"
      "          leg_offset_m: [-0.001, 0.0008, 0.0015, -0.0005, 0.001, 0.0]}\n");
  const std::string out = run_folder_ + "/pots.yaml";
  const std::string run_dir = run_folder_ + "/run";
  ASSERT_EQ(
      Identify(P16p() + "--plant hw --device-emulator --truth " + ShellQuote(truth) +
                   " --travel-speed 0.013 --lcm-url " + ShellQuote(PrivateLcmUrl(kHwLcmPort)) +
                   " --device-port " + std::to_string(kDevicePort) + " --local-port " +
                   std::to_string(kBridgePort) + " --run-dir " + ShellQuote(run_dir) + " --out " +
                   ShellQuote(out),
               true, "pots"),
      0)
      << ReadFile(Output()) << ReadFile(run_dir + "/hw_bridge.log");
  const StackConfig config = LoadStackConfig(DefaultConfigPath(), {DcMotorOverlayPath()});
  const StackConfig calibrated = LoadStackConfig(DefaultConfigPath(), {DcMotorOverlayPath(), out});
  const HwBridgeConfig& hw = config.hw_bridge;
  const double min_m = config.platform.leg_min_length_m;
  const double stroke_m = config.platform.leg_max_length_m - min_m;
  for (int i = 0; i < 6; ++i) {
    const double counts_per_m = (hw.adc_extended(i) - hw.adc_retracted(i)) / stroke_m;
    // The config's calibration inverted at the pot's reading s L + o.
    const auto counts_at = [&](double length_m) {
      return hw.adc_retracted(i) +
             (scale(i) * length_m + offset_m(i) - min_m - hw.length_offset_m(i)) * counts_per_m;
    };
    EXPECT_NEAR(calibrated.hw_bridge.adc_retracted(i), counts_at(min_m), 0.15e-3 * counts_per_m)
        << "leg " << i;
    EXPECT_NEAR(calibrated.hw_bridge.adc_extended(i), counts_at(min_m + stroke_m),
                0.15e-3 * counts_per_m)
        << "leg " << i;
  }
  const std::string bridge_log = ReadFile(run_dir + "/hw_bridge.log");
  EXPECT_NE(bridge_log.find("BRING-UP MODE"), std::string::npos) << bridge_log;
  // The bridge's end zones lie beyond the stroke ends, its fault margin wider.
  EXPECT_NE(bridge_log.find("end zones -0.0035 m"), std::string::npos) << bridge_log;
  EXPECT_NE(bridge_log.find("fault margin 114 counts"), std::string::npos) << bridge_log;
  EXPECT_NE(ReadFile(Output()).find("extended ends reached"), std::string::npos);
}

TEST_F(IdentifyActuatorsCli, PotsNeedTheHardwarePath) {
  const std::string out = " --out " + ShellQuote(run_folder_ + "/never.yaml");
  EXPECT_EQ(Identify(P16p() + "--plant sim" + out, false, "pots"), 2);
  EXPECT_NE(ReadFile(Output()).find("calibration is hw_bridge's"), std::string::npos)
      << ReadFile(Output());
  EXPECT_EQ(Identify("--plant hw --device-emulator --in-process" + out, false, "pots"), 2);
  EXPECT_NE(ReadFile(Output()).find("config/overlays/p16p.yaml"), std::string::npos)
      << ReadFile(Output());
  EXPECT_FALSE(std::filesystem::exists(run_folder_ + "/never.yaml"));
}

}  // namespace
}  // namespace stewart::test
