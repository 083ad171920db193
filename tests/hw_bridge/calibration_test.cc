#include "stewart/hw_bridge/calibration.h"

#include <gtest/gtest.h>

#include "stewart/config/sections.h"
#include "stewart/hw_bridge/drive_map.h"
#include "stewart/hw_bridge/wire_format.h"
#include "test_config.h"

namespace stewart::hw {
namespace {

HwBridgeConfig TestHw() {
  HwBridgeConfig hw = test::Config().hw_bridge;
  hw.adc_retracted << 200, 210, 3900, 190, 205, 220;  // leg 2: pot wired reversed
  hw.adc_extended << 3890, 3880, 180, 3900, 3895, 3870;
  hw.length_offset_m << 0.0, 0.001, -0.002, 0.0, 0.0005, 0.0;
  return hw;
}

TEST(LegCalibration, StrokeEndsMapToTheirLengths) {
  const HwBridgeConfig hw = TestHw();
  const LegCalibration cal(hw, 0.385, 0.2);
  for (int i = 0; i < 6; ++i) {
    EXPECT_NEAR(cal.LengthM(i, static_cast<uint16_t>(hw.adc_retracted(i))),
                0.385 + hw.length_offset_m(i), 1e-12);
    EXPECT_NEAR(cal.LengthM(i, static_cast<uint16_t>(hw.adc_extended(i))),
                0.585 + hw.length_offset_m(i), 1e-12);
  }
}

TEST(LegCalibration, InverseRoundTripsWithinHalfACount) {
  const LegCalibration cal(TestHw(), 0.385, 0.2);
  for (int i = 0; i < 6; ++i) {
    for (double l = 0.39; l < 0.58; l += 0.0137) {
      const double counts = cal.AdcCounts(i, l);
      const auto adc = static_cast<uint16_t>(std::lround(counts));
      const double count_m = 0.2 / std::abs(TestHw().adc_extended(i) - TestHw().adc_retracted(i));
      EXPECT_NEAR(cal.LengthM(i, adc), l, 0.5 * count_m + 1e-12) << "leg " << i;
    }
  }
}

TEST(LegCalibration, ReadingsOutsideTheSpanAreImplausible) {
  const HwBridgeConfig hw = TestHw();
  const LegCalibration cal(hw, 0.385, 0.2);
  EXPECT_TRUE(cal.Plausible(0, 200));
  EXPECT_TRUE(cal.Plausible(0, static_cast<uint16_t>(200 - hw.adc_fault_margin_counts)));
  EXPECT_FALSE(cal.Plausible(0, static_cast<uint16_t>(200 - hw.adc_fault_margin_counts - 1)));
  EXPECT_FALSE(cal.Plausible(0, 0));     // broken wiper / open wire
  EXPECT_FALSE(cal.Plausible(0, 4095));  // wiper shorted to the reference
  EXPECT_TRUE(cal.Plausible(2, 3900));   // reversed leg: its retracted end
  EXPECT_FALSE(cal.Plausible(2, 4000));
}

TEST(ImuScale, RawToSiAndSaturation) {
  const HwBridgeConfig& hw = test::Config().hw_bridge;
  const ImuScale imu(hw);
  const Vector3d g = imu.AccelMps2({0, 0, 8192});
  EXPECT_NEAR(g.z(), 9.81, 0.01);  // 4 g full scale: 8192 LSB per g
  std::array<int16_t, 3> raw{};
  EXPECT_TRUE(imu.GyroRaw(Vector3d(0.1, -0.2, 0.3), &raw));
  EXPECT_NEAR(imu.GyroRadps(raw).x(), 0.1, hw.gyro_radps_per_lsb);
  EXPECT_FALSE(imu.GyroRaw(Vector3d(100.0, 0, 0), &raw));
  EXPECT_EQ(raw[0], 32767);
  EXPECT_TRUE(ImuScale::Saturated(raw));
  EXPECT_FALSE(imu.AccelRaw(Vector3d(std::nan(""), 0, 0), &raw));
  EXPECT_EQ(raw[0], 0);
}

class DriveMapTest : public ::testing::Test {
 protected:
  HwBridgeConfig hw_ = test::Config().hw_bridge;
  double limit_ = 100.0;
};

TEST_F(DriveMapTest, FollowsTheDocumentedMapAndInverts) {
  hw_.force_at_full_duty_n = 120.0;
  hw_.duty_deadband = 0.1;
  hw_.force_deadzone_n = 0.5;
  const DriveMap map(hw_, limit_);
  Vector6d f;
  f << 0.0, 0.4, -0.6, 30.0, -60.0, 99.0;
  const DriveResult r = map.ForceToDrive(f);
  EXPECT_EQ(r.drive[0], 0);
  EXPECT_EQ(r.drive[1], 0);  // inside the deadzone
  EXPECT_EQ(r.drive[2], std::lround(-(0.1 + 0.9 * 0.6 / 120.0) * 32767));
  EXPECT_EQ(r.drive[3], std::lround((0.1 + 0.9 * 30.0 / 120.0) * 32767));
  EXPECT_EQ(r.force_clamped_mask, 0);
  EXPECT_EQ(r.duty_clamped_mask, 0);
  EXPECT_EQ(r.deadzone_mask, 0b000010);  // 0.4 N commanded, not applied; 0 N is no loss
  const Vector6d back = map.DriveToForce(r.drive);
  for (int i = 2; i < 6; ++i) EXPECT_NEAR(back(i), f(i), 120.0 / 32767 * 2) << i;
  EXPECT_EQ(back(1), 0.0);
}

TEST_F(DriveMapTest, ClampsForceAndDutyAndFlagsThem) {
  hw_.force_at_full_duty_n = 100.0;
  hw_.duty_deadband = 0.0;
  hw_.max_duty = 0.5;
  const DriveMap map(hw_, limit_);
  Vector6d f;
  f << 150.0, -1e9, 40.0, 60.0, -49.0, 0.0;
  const DriveResult r = map.ForceToDrive(f);
  EXPECT_EQ(r.drive[0], std::lround(0.5 * 32767));
  EXPECT_EQ(r.drive[1], -std::lround(0.5 * 32767));
  EXPECT_EQ(r.drive[2], std::lround(0.4 * 32767));
  EXPECT_EQ(r.drive[3], std::lround(0.5 * 32767));
  EXPECT_EQ(r.force_clamped_mask, 0b000011);
  EXPECT_EQ(r.duty_clamped_mask, 0b001011);
  for (int16_t d : r.drive) EXPECT_GE(d, -kDriveFullScale);
}

TEST_F(DriveMapTest, DriveSignReversesPerLegAndNonFiniteGivesZero) {
  hw_.drive_sign << 1, -1, 1, 1, 1, 1;
  const DriveMap map(hw_, limit_);
  Vector6d f;
  f << 20.0, 20.0, std::nan(""), INFINITY, -INFINITY, 0.0;
  const DriveResult r = map.ForceToDrive(f);
  EXPECT_GT(r.drive[0], 0);
  EXPECT_EQ(r.drive[1], -r.drive[0]);
  EXPECT_EQ(r.drive[2], 0);
  EXPECT_EQ(r.drive[3], 0);
  EXPECT_EQ(r.drive[4], 0);
  // The emulator's inverse uses the same wiring: the force comes back positive.
  EXPECT_NEAR(map.DriveToForce(r.drive)(1), 20.0, 0.01);
}

TEST_F(DriveMapTest, DeadbandDutyLocksTheLeg) {
  hw_.duty_deadband = 0.08;
  const DriveMap map(hw_, limit_);
  DriveArray d{0, static_cast<int16_t>(0.05 * 32767), static_cast<int16_t>(0.2 * 32767), 0, 0, 0};
  const auto locked = map.Locked(d);
  EXPECT_TRUE(locked[0]);
  EXPECT_TRUE(locked[1]);
  EXPECT_FALSE(locked[2]);
  EXPECT_EQ(map.DriveToForce(d)(1), 0.0);
}

TEST(HwBridgeConfig, BadValuesNameTheKey) {
  const ConfigNode good(YAML::Load(R"(
transport: udp
device_host: 127.0.0.1
device_port: 1
local_host: 127.0.0.1
local_port: 2
serial_device: /dev/null
serial_baud: 115200
command_timeout_s: 0.05
device_watchdog_s: 0.05
link_timeout_s: 0.1
late_frame_s: 0.005
clock_drift_ppm: 100
adc_max_count: 4095
adc_fault_margin_counts: 40
adc_retracted: [0, 0, 0, 0, 0, 0]
adc_extended: [4000, 4000, 4000, 4000, 4000, 50]
length_offset_m: [0, 0, 0, 0, 0, 0]
gyro_radps_per_lsb: 1.0e-4
accel_mps2_per_lsb: 1.0e-3
force_at_full_duty_n: 100
duty_deadband: 0.1
force_deadzone_n: 0.5
max_duty: 1.0
drive_sign: [1, 1, 1, 1, 1, 1]
)"),
                        "hw_bridge");
  try {
    ParseHwBridgeConfig(good, ActuatorConfig{});
    FAIL() << "degenerate calibration span accepted";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.key(), "hw_bridge.adc_extended");
  }
}

}  // namespace
}  // namespace stewart::hw
