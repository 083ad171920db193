// The pots' two-point calibration at the stroke ends (docs/hardware.md,
// "Calibrate the pots at the stroke ends"), in process: the stroke-end run
// against the device emulator behind hw_bridge's library in bring-up mode,
// whose pots read with scale and offset errors and whose motors are not the
// config's; the calibration it gives, its overlay; runs the guard or the
// checks stop; bad options.
#include "stewart/identify/pot_calibration.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <string>

#include "stewart/config/config_loader.h"
#include "stewart/config/default_config.h"
#include "stewart/hw_bridge/bringup.h"
#include "stewart/hw_bridge/calibration.h"
#include "stewart/identify/emulator_device.h"
#include "stewart/identify/inertial_fit.h"
#include "stewart/identify/stroke_end_procedure.h"
#include "stewart/model/kinematics.h"

namespace stewart::identify {
namespace {

const StackConfig& Config() { return DcMotorStackConfig(); }
double StrokeM() { return Config().platform.leg_max_length_m - Config().platform.leg_min_length_m; }

// Pots that read s_i L + o_i (the sensor model's scale and offset errors,
// 0.6-2.3 mm over the stroke), on motors 20 % slower and stronger.
PlantTruth PotsOff() {
  PlantTruth truth = TruthOfConfig(Config());
  truth.initial_pose = Config().home_pose;
  truth.sensor_errors.leg_scale << 1.003, 0.998, 1.0, 1.002, 0.997, 1.001;
  truth.sensor_errors.leg_offset_m << -0.001, 0.0008, 0.0015, -0.0005, 0.001, 0.0;
  truth.actuators.motor.stall_force_n *= 1.2;
  truth.actuators.motor.no_load_speed_mps *= 0.8;
  return truth;
}

StrokeEndOptions Options() {
  const StackConfig& c = Config();
  StrokeEndOptions o;
  o.min_length_m = c.platform.leg_min_length_m;
  o.max_length_m = c.platform.leg_max_length_m;
  o.motor = c.actuators.motor;
  o.speed_cap_mps =
      hw::DefaultBringupGuard(o.min_length_m, o.max_length_m, 0.001, o.motor).speed_cap_mps;
  return o;
}

// The device as stewart_identify --mode pots builds it: the bridge's guard
// the run's, its fault margin widened by the search.
struct Device {
  explicit Device(const PlantTruth& truth, const StrokeEndOptions& o = Options())
      : config(WithSearchMargin(o)), device(config, truth, Bringup(o)) {}
  static StackConfig WithSearchMargin(const StrokeEndOptions& o) {
    StackConfig c = Config();
    c.hw_bridge.adc_fault_margin_counts =
        hw::FaultMarginForSearch(c.hw_bridge, StrokeM(), o.search_m);
    return c;
  }
  static hw::BringupOptions Bringup(const StrokeEndOptions& o) {
    hw::BringupOptions b;
    b.enabled = true;
    b.guard = StrokeEndGuard(o);
    return b;
  }
  StackConfig config;
  EmulatorDevice device;
};

// The counts the emulator's pot gives at true length L: its reading
// s L + o, digitised with the inverse of the config's calibration.
double CountsAt(const PlantTruth& truth, int leg, double length_m) {
  const hw::LegCalibration in_use(Config().hw_bridge, Config().platform.leg_min_length_m,
                                  StrokeM());
  const double reading =
      truth.sensor_errors.leg_scale(leg) * length_m + truth.sensor_errors.leg_offset_m(leg);
  return in_use.AdcCounts(leg, reading);
}

TEST(PotCalibration, TheStrokeEndsGiveTheTwoPointCalibrationThroughTheEmulator) {
  const PlantTruth truth = PotsOff();
  Device d(truth);
  std::vector<std::string> progress;
  const StrokeEndRecord record = RunStrokeEndProcedure(
      &d.device, Options(), [&](const std::string& line) { progress.push_back(line); });
  const PotCalibration c = PotCalibrationFromEnds(
      Config().hw_bridge, Config().platform.leg_min_length_m, StrokeM(), record);
  ASSERT_EQ(progress.size(), 2u);
  std::printf("%s\n%s\n%.1f s, %ld samples\n", progress[0].c_str(), progress[1].c_str(),
              record.duration_s, record.samples);

  const double min_m = Config().platform.leg_min_length_m;
  const hw::LegCalibration before(Config().hw_bridge, min_m, StrokeM());
  HwBridgeConfig identified = Config().hw_bridge;
  identified.adc_retracted = c.adc_retracted;
  identified.adc_extended = c.adc_extended;
  const hw::LegCalibration after(identified, min_m, StrokeM());
  const Vector6d home_m = InverseKinematics(Config().platform, Config().home_pose);
  double worst_before_m = 0.0;
  for (int i = 0; i < kNumLegs; ++i) {
    // The ends' counts within 0.12 mm (the end stops' compliance under the
    // hold's push, ~0.05 mm, is in them), ...
    const double count_m = c.count_m(i);
    EXPECT_NEAR(c.adc_retracted(i), CountsAt(truth, i, min_m), 0.12e-3 / count_m) << "leg " << i;
    EXPECT_NEAR(c.adc_extended(i), CountsAt(truth, i, min_m + StrokeM()), 0.12e-3 / count_m)
        << "leg " << i;
    // The reading errors it reports: those of the calibration in use.
    const double old_count_m =
        StrokeM() / (Config().hw_bridge.adc_extended(i) - Config().hw_bridge.adc_retracted(i));
    EXPECT_NEAR(c.retracted_error_m(i),
                (CountsAt(truth, i, min_m) - before.AdcCounts(i, min_m)) * old_count_m, 0.12e-3);
    // ... and so a leg's length at home: within 0.1 mm now.
    const double counts_home = CountsAt(truth, i, home_m(i));
    const double error_before_m = (counts_home - before.AdcCounts(i, home_m(i))) * old_count_m;
    const double error_after_m = (counts_home - after.AdcCounts(i, home_m(i))) * StrokeM() /
                                 (c.adc_extended(i) - c.adc_retracted(i));
    std::printf("leg %d at home: %.3f mm before, %.3f mm after\n", i, 1e3 * error_before_m,
                1e3 * error_after_m);
    EXPECT_LT(std::abs(error_after_m), 0.1e-3) << "leg " << i;
    worst_before_m = std::max(worst_before_m, std::abs(error_before_m));
  }
  EXPECT_GT(worst_before_m, 1e-3);  // the pots were off
  // The platform is back where it started.
  EXPECT_LT((d.device.backend().plant().q() - Config().home_pose).head<3>().norm(), 2e-3);
}

// The message of the IdentificationError or GuardTrip the run ends with
// ("" if it finished).
std::string RunEndsWith(const PlantTruth& truth, const StrokeEndOptions& o = Options()) {
  Device d(truth, o);
  try {
    RunStrokeEndProcedure(&d.device, o);
  } catch (const IdentificationError& e) {
    return e.what();
  } catch (const GuardTrip& e) {
    return std::string("guard trip: ") + e.what();
  }
  return "";
}

// A pot reading 8 mm short: at the retracted end its leg would read 8 mm
// beyond the end, past the 4 mm search; the run stops there, says which leg
// and why, and does not push on.
TEST(PotCalibration, AReadingBeyondTheSearchStopsTheRun) {
  PlantTruth truth = PotsOff();
  truth.sensor_errors.leg_offset_m(2) = -0.008;
  const std::string why = RunEndsWith(truth);
  EXPECT_NE(why.find("leg 2"), std::string::npos) << why;
  EXPECT_NE(why.find("beyond its nominal stroke end"), std::string::npos) << why;
}

// A pot reading 14 mm long: its leg meets its retracted stop 14 mm before
// the end the run expects, while the others go on.
TEST(PotCalibration, ALegThatStopsEarlyStopsTheRun) {
  PlantTruth truth = PotsOff();
  truth.sensor_errors.leg_offset_m(4) = 0.014;
  const std::string why = RunEndsWith(truth);
  EXPECT_NE(why.find("leg 4"), std::string::npos) << why;
  EXPECT_TRUE(why.find("lags the others") != std::string::npos ||
              why.find("before its nominal retracted end") != std::string::npos)
      << why;
}

TEST(PotCalibration, TheOverlayAppliesOverTheP16pConfig) {
  StrokeEndRecord record;
  record.retracted_reading_m = Vector6d::Constant(Config().platform.leg_min_length_m + 0.001);
  record.extended_reading_m = Vector6d::Constant(Config().platform.leg_max_length_m - 0.0005);
  const PotCalibration c = PotCalibrationFromEnds(
      Config().hw_bridge, Config().platform.leg_min_length_m, StrokeM(), record);
  // One count is 0.054 mm: 1 mm long at the retracted end is 18.4 counts up.
  const double counts_per_m =
      (Config().hw_bridge.adc_extended(0) - Config().hw_bridge.adc_retracted(0)) / StrokeM();
  EXPECT_NEAR(c.adc_retracted(0), Config().hw_bridge.adc_retracted(0) + 1e-3 * counts_per_m, 1e-9);
  EXPECT_NEAR(c.adc_extended(0), Config().hw_bridge.adc_extended(0) - 0.5e-3 * counts_per_m, 1e-9);
  EXPECT_NEAR(c.retracted_error_m(3), 1e-3, 1e-12);
  EXPECT_NEAR(c.extended_error_m(3), -0.5e-3, 1e-12);

  const std::string path = ::testing::TempDir() + "/pots_" + std::to_string(::getpid()) + ".yaml";
  std::ofstream(path) << FormatPotOverlay(c, record, "a test\nline two");
  const StackConfig applied = LoadStackConfig(DefaultConfigPath(), {DcMotorOverlayPath(), path});
  for (int i = 0; i < kNumLegs; ++i) {
    EXPECT_NEAR(applied.hw_bridge.adc_retracted(i), c.adc_retracted(i), 0.006);
    EXPECT_NEAR(applied.hw_bridge.adc_extended(i), c.adc_extended(i), 0.006);
  }
  std::remove(path.c_str());

  // A pot that reads the same at both ends is broken, not calibrated.
  record.extended_reading_m = record.retracted_reading_m;
  EXPECT_THROW(PotCalibrationFromEnds(Config().hw_bridge, Config().platform.leg_min_length_m,
                                      StrokeM(), record),
               IdentificationError);
}

TEST(PotCalibration, BadOptionsAreRefused) {
  const auto refused = [](const std::function<void(StrokeEndOptions*)>& change) {
    StrokeEndOptions o = Options();
    change(&o);
    EXPECT_THROW(ValidateStrokeEndOptions(o), IdentificationError);
  };
  EXPECT_NO_THROW(ValidateStrokeEndOptions(Options()));
  refused([](StrokeEndOptions* o) { o->search_m = 0.0005; });
  refused([](StrokeEndOptions* o) { o->push_duty = 1.5; });
  refused([](StrokeEndOptions* o) { o->hold_duty = o->push_duty + 0.1; });
  refused([](StrokeEndOptions* o) { o->travel_speed_mps = o->speed_cap_mps; });
  refused([](StrokeEndOptions* o) { o->hold_s = NAN; });
  refused([](StrokeEndOptions* o) { o->max_length_m = o->min_length_m; });
  refused([](StrokeEndOptions* o) { o->motor = DcMotorParams{}; });
}

TEST(PotCalibration, TheBridgesFaultMarginReachesPastTheSearch) {
  const HwBridgeConfig& hw = Config().hw_bridge;
  // 3685 counts over 0.2 m: 4 mm is 73.7 counts, rounded up, on top of 40.
  EXPECT_EQ(hw::FaultMarginForSearch(hw, StrokeM(), 0.004), hw.adc_fault_margin_counts + 74);
  const hw::LegGuardLimits g = hw::StrokeEndSearchGuard(0.385, 0.585, 0.004, 0.03);
  EXPECT_DOUBLE_EQ(g.min_length_m, 0.381);
  EXPECT_DOUBLE_EQ(g.max_length_m, 0.589);
  EXPECT_GT(g.margin_m, 0.0);
  EXPECT_LT(g.margin_m, 0.001);
}

}  // namespace
}  // namespace stewart::identify
