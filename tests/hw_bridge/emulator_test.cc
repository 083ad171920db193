#include <gtest/gtest.h>

#include "stewart/hw_bridge/bridge.h"
#include "stewart/hw_emulator/device_emulator.h"
#include "stewart/hw_emulator/model_backend.h"
#include "stewart/model/kinematics.h"
#include "test_config.h"

namespace stewart::hw {
namespace {

class RecordingBackend : public DeviceBackend {
 public:
  void Step(const DriveArray& drive, double) override { last = drive; }
  RawReadings Sample() override { return {}; }
  DriveArray last{};
};

CommandFrame Command(uint32_t seq, int16_t drive, uint32_t watchdog_us = 50000) {
  CommandFrame c;
  c.seq = seq;
  c.watchdog_us = watchdog_us;
  c.drive.fill(drive);
  return c;
}

TEST(DeviceWatchdog, ZeroDriveWhenCommandsStop) {
  RecordingBackend backend;
  DeviceEmulator device(&backend);
  SensorFrame f = device.Tick(1000, 1e-3);
  EXPECT_NE(f.status & kStatusActuatorsOff, 0);  // no command yet
  device.OnCommandFrame(Command(1, 5000, 20000), 1000);
  f = device.Tick(2000, 1e-3);
  EXPECT_EQ(backend.last[0], 5000);
  EXPECT_EQ(f.status, 0);
  EXPECT_EQ(f.last_command_seq, 1U);
  EXPECT_EQ(f.command_age_us, 1000U);
  f = device.Tick(21000, 1e-3);  // exactly the watchdog period: still in force
  EXPECT_EQ(backend.last[0], 5000);
  f = device.Tick(21001, 1e-3);
  EXPECT_EQ(backend.last[0], 0);
  EXPECT_NE(f.status & kStatusWatchdog, 0);
  EXPECT_EQ(f.applied_drive[0], 0);
  device.OnCommandFrame(Command(2, 7000, 20000), 22000);  // commands resume
  f = device.Tick(23000, 1e-3);
  EXPECT_EQ(backend.last[0], 7000);
  EXPECT_EQ(f.status & kStatusWatchdog, 0);
}

TEST(DeviceWatchdog, EnableBitOffAndSeqBookkeeping) {
  RecordingBackend backend;
  DeviceEmulator device(&backend);
  CommandFrame c = Command(10, 3000);
  c.flags = 0;
  device.OnCommandFrame(c, 0);
  SensorFrame f = device.Tick(1000, 1e-3);
  EXPECT_EQ(backend.last[0], 0);
  EXPECT_NE(f.status & kStatusActuatorsOff, 0);
  device.OnCommandFrame(Command(14, 3000), 1000);   // 11..13 lost
  device.OnCommandFrame(Command(12, -3000), 1100);  // reordered: ignored
  device.OnRxError();
  f = device.Tick(2000, 1e-3);
  EXPECT_EQ(backend.last[0], 3000);
  EXPECT_EQ(f.rx_lost, 3U);
  EXPECT_EQ(f.rx_corrupt, 1U);
}

class ModelBackendTest : public ::testing::Test {
 protected:
  ModelBackend Make(bool noise) {
    const StackConfig& c = test::Config();
    ModelBackendOptions o;
    o.noise = noise;
    return ModelBackend(c.platform, c.actuators, c.sensors, c.hw_bridge, c.home_pose,
                        Vector6d::Zero(), o);
  }
};

TEST_F(ModelBackendTest, ZeroDriveHoldsThePose) {
  ModelBackend backend = Make(false);
  const Vector6d q0 = backend.q();
  for (int k = 0; k < 200; ++k) backend.Step(DriveArray{}, 1e-3);
  EXPECT_LT((backend.q() - q0).norm(), 1e-12);
  const RawReadings raw = backend.Sample();
  const ImuScale imu(test::Config().hw_bridge);
  EXPECT_NEAR(imu.AccelMps2(raw.accel_raw).z(), test::Config().platform.gravity_mps2, 0.01);
  EXPECT_EQ(raw.status, 0);
}

TEST_F(ModelBackendTest, GravityCompensationThroughTheBridgeMapHoldsStill) {
  // The bridge's map forward, the emulator's inverse: the gravity-compensating
  // forces keep the platform nearly still (only drive quantisation remains).
  const StackConfig& c = test::Config();
  ModelBackend backend = Make(false);
  const DriveMap map(c.hw_bridge, c.actuators.force_limit_n);
  const DynamicsTerms terms = EvaluateDynamics(c.platform, c.home_pose, Vector6d::Zero());
  const Vector6d f_hold = InverseDynamics(terms, Vector6d::Zero());
  const DriveArray drive = map.ForceToDrive(f_hold).drive;
  for (int k = 0; k < 500; ++k) backend.Step(drive, 1e-3);
  EXPECT_LT((backend.q() - c.home_pose).head<3>().norm(), 1e-3);
  EXPECT_LT(backend.qd().norm(), 1e-2);
  // ...and extra force on every leg raises it.
  DriveArray up = map.ForceToDrive(f_hold + Vector6d::Constant(5.0)).drive;
  for (int k = 0; k < 200; ++k) backend.Step(up, 1e-3);
  EXPECT_GT(backend.q()(2), c.home_pose(2) + 1e-3);
}

TEST_F(ModelBackendTest, SamplesDecodeBackToTheTrueLegLengths) {
  const StackConfig& c = test::Config();
  ModelBackend backend = Make(true);
  const LegCalibration cal(c.hw_bridge, c.platform.leg_min_length_m,
                           c.platform.leg_max_length_m - c.platform.leg_min_length_m);
  const Vector6d truth = InverseKinematics(c.platform, backend.q());
  const RawReadings raw = backend.Sample();
  const double count_m = (c.platform.leg_max_length_m - c.platform.leg_min_length_m) /
                         (c.hw_bridge.adc_extended(0) - c.hw_bridge.adc_retracted(0));
  for (int i = 0; i < 6; ++i) {
    EXPECT_NEAR(cal.LengthM(i, raw.adc[static_cast<std::size_t>(i)]), truth(i),
                count_m + 5 * c.sensors.leg_pot_noise_std_m);
  }
}

}  // namespace
}  // namespace stewart::hw
