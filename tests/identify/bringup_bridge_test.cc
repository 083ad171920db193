// hw_bridge's bring-up mode in its library (hw_bridge/bringup.h): duty
// commands instead of force commands, the leg guard on the bridge's own
// readings, zero drive when commands stop, and the echo of what the device
// applied (docs/hardware.md, "Identify the actuators"). Also the guard
// (hw_bridge/leg_guard.h) itself.
#include <gtest/gtest.h>

#include <cmath>

#include "stewart/config/default_config.h"
#include "stewart/hw_bridge/bridge.h"
#include "stewart/hw_bridge/leg_guard.h"

namespace stewart::hw {
namespace {

constexpr double kMinLengthM = 0.385;
constexpr double kStrokeM = 0.2;

class BringupBridgeTest : public ::testing::Test {
 protected:
  BringupBridgeTest()
      : hw_(DcMotorStackConfig().hw_bridge),
        calibration_(hw_, kMinLengthM, kStrokeM),
        bridge_(hw_, kMinLengthM, kStrokeM, DcMotorStackConfig().actuators.force_limit_n,
                Options()) {
    lengths_m_.setConstant(0.45);
  }

  static BringupOptions Options() {
    BringupOptions b;
    b.enabled = true;
    b.guard = DefaultBringupGuard(kMinLengthM, kMinLengthM + kStrokeM, 0.005,
                                  DcMotorStackConfig().actuators.motor);
    return b;
  }

  // Sample k (device time k ms) with the legs at lengths_m_, each advanced
  // by speeds_mps_ first; the frame echoes command `echo_seq`, held for
  // `age_us`, and the drive the device applied.
  bool Deliver(uint32_t k, uint32_t echo_seq = 0, uint32_t age_us = 0,
               const DriveArray& applied = {}, uint16_t status = 0) {
    lengths_m_ += 1e-3 * speeds_mps_;
    SensorFrame f;
    f.seq = k;
    f.device_time_us = 1000ULL * k;
    for (int i = 0; i < 6; ++i) {
      f.adc[static_cast<std::size_t>(i)] =
          static_cast<uint16_t>(std::lround(calibration_.AdcCounts(i, lengths_m_(i))));
    }
    f.accel_raw = {0, 0, 8192};
    f.last_command_seq = echo_seq;
    f.command_age_us = age_us;
    f.applied_drive = applied;
    f.status = status;
    f.command_session = bridge_.link_session();  // the device follows this bridge
    host_now_ = kHostEpoch + 1000 * static_cast<int64_t>(k) + 100;
    return bridge_.OnSensorFrame(f, host_now_, &sample_);
  }

  DriveArray Send() {
    std::array<uint8_t, kMaxFrameSize> buf{};
    const std::size_t n = bridge_.BuildCommandFrame(host_now_, buf.data());
    DecodedFrame out;
    EXPECT_EQ(DecodeDatagram(buf.data(), n, &out), DecodeStatus::kOk);
    return out.command.drive;
  }

  static Vector6d Duty(double d0, double d1 = 0.0) {
    Vector6d d = Vector6d::Zero();
    d(0) = d0;
    d(1) = d1;
    return d;
  }

  static constexpr int64_t kHostEpoch = 1'000'000'000'000;
  HwBridgeConfig hw_;
  LegCalibration calibration_;
  HwBridge bridge_;
  SensorSample sample_;
  int64_t host_now_ = 0;
  Vector6d lengths_m_;
  Vector6d speeds_mps_ = Vector6d::Zero();
};

TEST_F(BringupBridgeTest, TakesDutyCommandsAndRefusesForceCommands) {
  HwBridge normal(hw_, kMinLengthM, kStrokeM, 100.0);
  EXPECT_FALSE(normal.bringup());
  EXPECT_EQ(normal.OnDutyCommand(0, Duty(0.5)), CommandVerdict::kWrongMode);

  for (uint32_t k = 0; k < 30; ++k) ASSERT_TRUE(Deliver(k));
  EXPECT_TRUE(bridge_.bringup());
  ForceCommand force;
  force.utime = force.sample_utime = sample_.utime;
  force.force_n = Vector6d::Constant(5.0);
  EXPECT_EQ(bridge_.OnSafeCommand(force, true), CommandVerdict::kWrongMode);
  Vector6d duty;
  duty << 0.5, -0.25, 0.0, 1.5, NAN, -1.0;
  EXPECT_EQ(bridge_.OnDutyCommand(sample_.utime, duty), CommandVerdict::kNonFinite);
  EXPECT_EQ(Send(), DriveArray{});
  EXPECT_EQ(bridge_.last_reason(), DriveReason::kInvalid);
  duty(4) = 0.1;
  ASSERT_EQ(bridge_.OnDutyCommand(sample_.utime, duty), CommandVerdict::kAccepted);
  const DriveArray drive = Send();
  EXPECT_EQ(bridge_.last_reason(), DriveReason::kCommand);
  EXPECT_EQ(drive[0], std::lround(0.5 * kDriveFullScale));
  EXPECT_EQ(drive[1], std::lround(-0.25 * kDriveFullScale));
  EXPECT_EQ(drive[2], 0);
  EXPECT_EQ(drive[3], kDriveFullScale);  // clamped to max_duty
  EXPECT_EQ(drive[5], -kDriveFullScale);
  EXPECT_EQ(bridge_.counters().duty_clamped, 1u);
  EXPECT_EQ(bridge_.Health(host_now_, "test").state, LinkState::kOk);
}

TEST_F(BringupBridgeTest, ZeroDriveWhenDutyCommandsStop) {
  for (uint32_t k = 0; k < 30; ++k) ASSERT_TRUE(Deliver(k));
  ASSERT_EQ(bridge_.OnDutyCommand(sample_.utime, Duty(0.4)), CommandVerdict::kAccepted);
  EXPECT_NE(Send()[0], 0);
  const auto timeout_ms = static_cast<uint32_t>(hw_.command_timeout_s * 1e3);
  // The command answers sample 29: at sample 29 + timeout it is exactly
  // command_timeout_s old and still in force, one sample later stale.
  for (uint32_t k = 30; k <= 29 + timeout_ms; ++k) ASSERT_TRUE(Deliver(k));
  EXPECT_NE(Send()[0], 0);
  ASSERT_TRUE(Deliver(30 + timeout_ms));
  EXPECT_EQ(Send()[0], 0);
  EXPECT_EQ(bridge_.last_reason(), DriveReason::kStale);
  EXPECT_EQ(bridge_.Health(host_now_, "test").error, "zero drive: stale duty command (bring-up)");
}

TEST_F(BringupBridgeTest, GuardAllowsOnlyDutyAwayFromANearEnd) {
  lengths_m_(0) = kMinLengthM + 0.002;  // inside the 5 mm end zone
  lengths_m_(1) = kMinLengthM + kStrokeM - 0.001;
  for (uint32_t k = 0; k < 30; ++k) ASSERT_TRUE(Deliver(k));
  ASSERT_EQ(bridge_.OnDutyCommand(sample_.utime, Duty(-0.5, 0.5)), CommandVerdict::kAccepted);
  DriveArray drive = Send();
  EXPECT_EQ(drive[0], 0);
  EXPECT_EQ(drive[1], 0);
  EXPECT_EQ(bridge_.counters().guard_limited_frames, 1u);
  ASSERT_EQ(bridge_.OnDutyCommand(sample_.utime, Duty(0.5, -0.5)), CommandVerdict::kAccepted);
  drive = Send();
  EXPECT_GT(drive[0], 0);
  EXPECT_LT(drive[1], 0);
  EXPECT_EQ(bridge_.guard().tripped_mask(), 0);
}

// A leg that moves towards the end inside its zone under a duty pointing
// away (its motor is wired reversed) trips; the zero goes out with the
// sample that tripped it, and stays until a zero command re-arms the leg.
TEST_F(BringupBridgeTest, GuardTripsALegMovingIntoItsEnd) {
  lengths_m_(0) = kMinLengthM + 0.004;
  for (uint32_t k = 0; k < 30; ++k) ASSERT_TRUE(Deliver(k));
  ASSERT_EQ(bridge_.OnDutyCommand(sample_.utime, Duty(0.5)), CommandVerdict::kAccepted);
  EXPECT_GT(Send()[0], 0);
  speeds_mps_(0) = -0.01;
  uint32_t k = 30;
  while (bridge_.guard().tripped_mask() == 0 && k < 100) {
    ASSERT_TRUE(Deliver(k++));
    if (bridge_.guard().tripped_mask() == 0) {
      ASSERT_EQ(bridge_.OnDutyCommand(sample_.utime, Duty(0.5)), CommandVerdict::kAccepted);
      Send();
    }
  }
  EXPECT_EQ(bridge_.guard().reason(0), GuardReason::kRetractedEnd);
  EXPECT_GT(sample_.leg_length_m(0), kMinLengthM + 0.001);  // well before the end
  EXPECT_TRUE(bridge_.TickFrameDue());
  EXPECT_EQ(Send()[0], 0);
  EXPECT_EQ(bridge_.counters().guard_trips, 1u);
  EXPECT_EQ(bridge_.Health(host_now_, "test").state, LinkState::kDegraded);
  // Stopped (a window without motion): held until a zero command re-arms it.
  speeds_mps_(0) = 0.0;
  for (int n = 0; n < 30; ++n) ASSERT_TRUE(Deliver(k++));
  ASSERT_EQ(bridge_.OnDutyCommand(sample_.utime, Duty(0.5)), CommandVerdict::kAccepted);
  EXPECT_EQ(Send()[0], 0);
  ASSERT_EQ(bridge_.OnDutyCommand(sample_.utime, Duty(0.0)), CommandVerdict::kAccepted);
  Send();
  ASSERT_TRUE(Deliver(k++));
  ASSERT_EQ(bridge_.OnDutyCommand(sample_.utime, Duty(0.5)), CommandVerdict::kAccepted);
  EXPECT_GT(Send()[0], 0);
}

TEST_F(BringupBridgeTest, GuardTripsALegFasterThanTheCap) {
  for (uint32_t k = 0; k < 30; ++k) ASSERT_TRUE(Deliver(k));
  ASSERT_EQ(bridge_.OnDutyCommand(sample_.utime, Duty(0.3, 0.8)), CommandVerdict::kAccepted);
  Send();
  speeds_mps_(1) = 2.0 * Options().guard.speed_cap_mps;
  for (uint32_t k = 30; k < 60; ++k) ASSERT_TRUE(Deliver(k));
  EXPECT_EQ(bridge_.guard().reason(1), GuardReason::kSpeed);
  const DriveArray drive = Send();
  EXPECT_GT(drive[0], 0);  // the other legs keep their duty
  EXPECT_EQ(drive[1], 0);
  EXPECT_NE(bridge_.Health(host_now_, "test").error.find("leg 1 (speed_cap)"), std::string::npos);
}

TEST_F(BringupBridgeTest, EchoesWhatTheDeviceAppliedAndSinceWhen) {
  ASSERT_TRUE(Deliver(0));
  EXPECT_EQ(bridge_.applied().since_utime, 0);  // nothing applied yet
  ASSERT_EQ(bridge_.OnDutyCommand(sample_.utime, Duty(0.5)), CommandVerdict::kAccepted);
  Send();
  DriveArray applied{};
  applied[0] = static_cast<int16_t>(std::lround(0.5 * kDriveFullScale));
  ASSERT_TRUE(Deliver(1, 1, 700, applied));
  EXPECT_EQ(bridge_.applied().sample_utime, sample_.utime);
  EXPECT_EQ(bridge_.applied().since_utime, sample_.utime - 700);
  EXPECT_NEAR(bridge_.applied().duty(0), 0.5, 1e-4);
  EXPECT_FALSE(bridge_.applied().device_watchdog);
  // A later frame with the same drive (a keep-alive, or two commands in a
  // row) does not move the time of the change.
  const int64_t changed_at = bridge_.applied().since_utime;
  ASSERT_TRUE(Deliver(2, 2, 200, applied));
  EXPECT_EQ(bridge_.applied().since_utime, changed_at);
  // The device's watchdog cut the drive at arrival + watchdog_us.
  const auto watchdog_us = static_cast<int64_t>(std::lround(hw_.device_watchdog_s * 1e6));
  ASSERT_TRUE(Deliver(80, 1, 79'300, DriveArray{}, kStatusWatchdog));
  EXPECT_TRUE(bridge_.applied().device_watchdog);
  EXPECT_EQ(bridge_.applied().since_utime, sample_.utime - 79'300 + watchdog_us);
  EXPECT_EQ(bridge_.applied().duty, Vector6d::Zero());
}

TEST(LegGuard, SpeedIsTheSlopeOverAFullWindow) {
  LegSpeedEstimator speed;
  for (int k = 0; k < LegSpeedEstimator::kWindow - 1; ++k) {
    speed.Add(1000 * k, 0.4 + 0.02 * 1e-3 * k);
    EXPECT_EQ(speed.speed_mps(), 0.0);  // not yet a full window
  }
  speed.Add(1000 * (LegSpeedEstimator::kWindow - 1),
            0.4 + 0.02 * 1e-3 * (LegSpeedEstimator::kWindow - 1));
  EXPECT_NEAR(speed.speed_mps(), 0.02, 1e-9);
  speed.Add(1000 * LegSpeedEstimator::kWindow + LegSpeedEstimator::kMaxGapUs + 1, 0.5);
  EXPECT_EQ(speed.speed_mps(), 0.0);  // a gap restarts the window
}

TEST(LegGuard, BadReadingsTripAndZeroDutyReArms) {
  LegGuardLimits limits;
  limits.min_length_m = kMinLengthM;
  limits.max_length_m = kMinLengthM + kStrokeM;
  LegGuard guard(limits);
  Vector6d lengths = Vector6d::Constant(0.45);
  lengths(2) = NAN;
  EXPECT_EQ(guard.Update(0, lengths), 1 << 2);
  EXPECT_EQ(guard.reason(2), GuardReason::kReading);
  Vector6d duty = Vector6d::Constant(0.5);
  EXPECT_EQ(guard.Apply(duty)(2), 0.0);
  EXPECT_EQ(guard.limited_mask(), 1 << 2);
  EXPECT_EQ(guard.Update(1000, Vector6d::Constant(0.45), 0x3F & ~(1 << 4)), 1 << 4);
  duty(2) = 0.0;
  guard.Apply(duty);  // leg 2 reads well again: re-armed
  EXPECT_EQ(guard.tripped_mask(), 1 << 4);
  duty(2) = NAN;
  EXPECT_EQ(guard.Apply(duty)(2), 0.0);  // a non-finite duty is zero
}

}  // namespace
}  // namespace stewart::hw
