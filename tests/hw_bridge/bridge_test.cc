#include "stewart/hw_bridge/bridge.h"

#include <gtest/gtest.h>

#include <optional>

#include "test_config.h"

namespace stewart::hw {
namespace {

constexpr int64_t kSession = 77;

/// A safe command of session kSession, announced first when the bridge
/// follows no session yet (the safety process does the same before its
/// first command). seq increases over the whole test binary.
CommandVerdict Command(HwBridge& bridge, int64_t sample_utime, const Vector6d& force,
                       int32_t flags = 0) {
  static int64_t seq = 0;
  if (!bridge.acceptor().has_session()) {
    bridge.OnAnnouncement({bridge.latest_sample_utime(), 1, kSession}, true, 0);
  }
  ForceCommand c;
  c.utime = c.sample_utime = sample_utime;
  c.seq = ++seq;
  c.force_n = force;
  c.flags = flags;
  c.session_id = kSession;
  return bridge.OnSafeCommand(c, true);
}

class BridgeTest : public ::testing::Test {
 protected:
  BridgeTest()
      : hw_(test::Config().hw_bridge),
        bridge_(hw_, 0.385, 0.2, test::Config().actuators.force_limit_n) {}

  // A device sample: seq k taken at device time k ms, arriving `delay_us` later
  // on a host clock whose epoch is 1e12 us.
  bool Deliver(uint32_t k, int64_t delay_us = 100, uint32_t echo_seq = 0, uint32_t age_us = 0) {
    SensorFrame f;
    f.seq = k;
    f.device_time_us = 1000ULL * k;
    f.adc.fill(2000);
    f.accel_raw = {0, 0, 8192};
    f.last_command_seq = echo_seq;
    f.command_age_us = age_us;
    // The device follows this bridge unless a test says otherwise.
    f.command_session = device_session_.value_or(bridge_.link_session());
    host_now_ = kHostEpoch + 1000 * static_cast<int64_t>(k) + delay_us;
    return bridge_.OnSensorFrame(f, host_now_, &sample_);
  }

  DecodedFrame Send() {
    std::array<uint8_t, kMaxFrameSize> buf{};
    const std::size_t n = bridge_.BuildCommandFrame(host_now_, buf.data());
    DecodedFrame out;
    EXPECT_EQ(DecodeDatagram(buf.data(), n, &out), DecodeStatus::kOk);
    return out;
  }

  static constexpr int64_t kHostEpoch = 1'000'000'000'000;
  HwBridgeConfig hw_;
  HwBridge bridge_;
  SensorSample sample_;
  int64_t host_now_ = 0;
  std::optional<uint32_t> device_session_;  // the session the device echoes; none: the bridge's
};

TEST_F(BridgeTest, SampleInSiUnitsOnTheHostTimeBase) {
  ASSERT_TRUE(Deliver(0, 300));
  ASSERT_TRUE(Deliver(1, 100));
  const LegCalibration cal(hw_, 0.385, 0.2);
  EXPECT_DOUBLE_EQ(sample_.leg_length_m(3), cal.LengthM(3, 2000));
  EXPECT_NEAR(sample_.accel_mps2.z(), 9.81, 0.01);
  EXPECT_EQ(sample_.status, 0);
  // Offset = least observed delay (100 us) -> utime = host time of sampling + 100.
  EXPECT_EQ(sample_.utime, kHostEpoch + 1000 + 100);
  ASSERT_TRUE(Deliver(2, 2000));  // a slow frame does not move the mapping
  EXPECT_EQ(sample_.utime, kHostEpoch + 2000 + 100);
}

TEST_F(BridgeTest, CountsLostLateAndReorderedFrames) {
  Deliver(0);
  Deliver(1);
  Deliver(5);  // 2, 3, 4 lost
  EXPECT_EQ(bridge_.counters().lost_frames, 3U);
  EXPECT_FALSE(Deliver(4));  // late arrival of an old one: dropped, not published
  EXPECT_FALSE(Deliver(5));  // duplicate
  EXPECT_EQ(bridge_.counters().reordered_frames, 2U);
  Deliver(6, 100 + static_cast<int64_t>(hw_.late_frame_s * 1e6) + 1);
  EXPECT_EQ(bridge_.counters().late_frames, 1U);
  EXPECT_EQ(bridge_.counters().sensor_frames, 4U);
}

TEST_F(BridgeTest, MissingCommandGivesZeroDrive) {
  Deliver(0);
  const DecodedFrame f = Send();
  EXPECT_EQ(bridge_.last_reason(), DriveReason::kMissing);
  for (int16_t d : f.command.drive) EXPECT_EQ(d, 0);
  // ENABLE clear: the device's samples say the actuators are off, so the
  // estimator predicts the legs held, not moved by a command.
  EXPECT_EQ(f.command.flags & kCommandEnable, 0);
  EXPECT_EQ(f.command.watchdog_us, static_cast<uint32_t>(hw_.device_watchdog_s * 1e6));
  EXPECT_EQ(bridge_.counters().zero_drive_frames, 1U);
}

TEST_F(BridgeTest, FreshCommandIsMappedAndStaleOneZeroed) {
  Deliver(0);
  Deliver(1);
  const Vector6d force = Vector6d::Constant(20.0);
  ASSERT_EQ(Command(bridge_, sample_.utime, force), CommandVerdict::kAccepted);
  DecodedFrame f = Send();
  EXPECT_EQ(bridge_.last_reason(), DriveReason::kCommand);
  const DriveResult expected = DriveMap(hw_, 100.0).ForceToDrive(force);
  EXPECT_EQ(f.command.drive, expected.drive);
  EXPECT_NE(f.command.flags & kCommandEnable, 0);
  // The stack's time moves on (new samples) but no new command: stale after
  // command_timeout_s of sample time, whatever the wall clock does.
  const auto timeout_ms = static_cast<uint32_t>(hw_.command_timeout_s * 1e3);
  Deliver(1 + timeout_ms);
  f = Send();
  EXPECT_EQ(bridge_.last_reason(), DriveReason::kCommand);
  Deliver(2 + timeout_ms);
  f = Send();
  EXPECT_EQ(bridge_.last_reason(), DriveReason::kStale);
  for (int16_t d : f.command.drive) EXPECT_EQ(d, 0);
  EXPECT_EQ(f.command.flags & kCommandEnable, 0);
}

// A bridge that was not running (SIGSTOP, a starved CPU) reads the device's
// frames queued meanwhile: against those old samples the command from
// before the stall looks young, but on the host's clock it is not.
TEST_F(BridgeTest, AfterAStallAQueuedFrameDoesNotMakeAnOldCommandYoung) {
  Deliver(0);
  Deliver(1);
  ASSERT_EQ(Command(bridge_, sample_.utime, Vector6d::Constant(20.0)), CommandVerdict::kAccepted);
  Send();
  EXPECT_EQ(bridge_.last_reason(), DriveReason::kCommand);
  // Sample 2 was queued 2 s ago; the bridge reads it only now.
  Deliver(2, 2'000'000);
  const DecodedFrame f = Send();
  EXPECT_EQ(bridge_.last_reason(), DriveReason::kStale);
  for (int16_t d : f.command.drive) EXPECT_EQ(d, 0);
  EXPECT_EQ(f.command.flags & kCommandEnable, 0);
}

TEST_F(BridgeTest, ForcesInTheDeadZoneAreCounted) {
  // A commanded force the dead zone drops is counted per leg and frame: the
  // rest of the stack assumes the commanded force acts.
  hw_.force_deadzone_n = 0.5;
  HwBridge bridge(hw_, 0.385, 0.2, 100.0);
  SensorFrame frame;
  frame.adc.fill(2000);
  frame.command_session = bridge.link_session();  // the device follows this bridge
  SensorSample sample;
  ASSERT_TRUE(bridge.OnSensorFrame(frame, kHostEpoch, &sample));
  Vector6d force = Vector6d::Constant(2.0);
  force(1) = 0.3;
  force(4) = -0.2;
  ASSERT_EQ(Command(bridge, sample.utime, force), CommandVerdict::kAccepted);
  std::array<uint8_t, kMaxFrameSize> buffer{};
  bridge.BuildCommandFrame(kHostEpoch, buffer.data());
  bridge.BuildCommandFrame(kHostEpoch + 500, buffer.data());
  EXPECT_EQ(bridge.counters().force_deadzoned, 4U);
  EXPECT_EQ(bridge.counters().zero_drive_frames, 0U);
}

TEST_F(BridgeTest, NonFiniteCommandZeroesUntilAValidOne) {
  Deliver(0);
  ASSERT_EQ(Command(bridge_, sample_.utime, Vector6d::Constant(10.0)), CommandVerdict::kAccepted);
  Vector6d bad = Vector6d::Constant(10.0);
  bad(4) = std::nan("");
  EXPECT_EQ(Command(bridge_, sample_.utime, bad), CommandVerdict::kNonFinite);
  DecodedFrame f = Send();
  EXPECT_EQ(bridge_.last_reason(), DriveReason::kInvalid);
  for (int16_t d : f.command.drive) EXPECT_EQ(d, 0);
  ASSERT_EQ(Command(bridge_, sample_.utime, Vector6d::Constant(10.0)), CommandVerdict::kAccepted);
  f = Send();
  EXPECT_EQ(bridge_.last_reason(), DriveReason::kCommand);
  EXPECT_GT(f.command.drive[0], 0);
}

TEST_F(BridgeTest, CommandsFromAnotherTimeBaseOrOutOfOrderAreIgnored) {
  // No sample yet: no session can be announced, so nothing is trusted.
  EXPECT_EQ(Command(bridge_, 5, Vector6d::Zero()), CommandVerdict::kUntrusted);
  EXPECT_EQ(bridge_.last_rejection(), CommandRejection::kNoSession);
  Deliver(0);
  Deliver(1);
  EXPECT_EQ(Command(bridge_, sample_.utime + 10'000'000, Vector6d::Zero()),
            CommandVerdict::kUntrusted);
  EXPECT_EQ(bridge_.last_rejection(), CommandRejection::kFutureSample);
  // Never ahead of the newest sample, not even by one microsecond.
  EXPECT_EQ(Command(bridge_, sample_.utime + 1, Vector6d::Zero()), CommandVerdict::kUntrusted);
  ASSERT_EQ(Command(bridge_, sample_.utime, Vector6d::Constant(5.0)), CommandVerdict::kAccepted);
  EXPECT_EQ(Command(bridge_, sample_.utime - 1000, Vector6d::Constant(50.0)),
            CommandVerdict::kOutOfOrder);
  EXPECT_EQ(Send().command.drive, DriveMap(hw_, 100.0).ForceToDrive(Vector6d::Constant(5.0)).drive);
}

TEST_F(BridgeTest, OneKeepAliveFramePerTickWithoutCommands) {
  Deliver(0);
  EXPECT_TRUE(bridge_.TickFrameDue());
  Send();
  EXPECT_FALSE(bridge_.TickFrameDue());
  Deliver(1);
  EXPECT_FALSE(bridge_.TickFrameDue());  // a frame went out during the last period
  Deliver(2);
  EXPECT_TRUE(bridge_.TickFrameDue());
}

TEST_F(BridgeTest, RoundTripExcludesTheDeviceHoldTime) {
  Deliver(0);
  const DecodedFrame f = Send();  // sent at host_now_
  const int64_t sent_at = host_now_;
  // Echoed with the frame of sample 3, held 400 us by the device.
  Deliver(3, 100, f.command.seq, 400);
  EXPECT_EQ(bridge_.counters().rtt_us.count, 1);
  EXPECT_EQ(bridge_.counters().rtt_us.last, host_now_ - sent_at - 400);
  Deliver(4, 100, f.command.seq, 1400);  // the same seq again: not a new sample
  EXPECT_EQ(bridge_.counters().rtt_us.count, 1);
}

TEST_F(BridgeTest, AnotherSessionsSeqIsNoRoundTrip) {
  Deliver(0);
  const DecodedFrame f = Send();
  // The device still follows the bridge before this one, whose frame had
  // the same seq: not this bridge's round trip.
  device_session_ = 99U;
  Deliver(1, 100, f.command.seq, 400);
  EXPECT_EQ(bridge_.counters().rtt_us.count, 0);
  device_session_.reset();
  Deliver(2, 100, f.command.seq, 400);
  EXPECT_EQ(bridge_.counters().rtt_us.count, 1);
}

TEST_F(BridgeTest, ImplausibleAdcAndSaturatedImuAreFlagged) {
  SensorFrame f;
  f.seq = 0;
  f.adc.fill(2000);
  f.adc[2] = 0;
  f.gyro_raw = {32767, 0, 0};
  ASSERT_TRUE(bridge_.OnSensorFrame(f, kHostEpoch, &sample_));
  EXPECT_NE(sample_.status & kStatusLegFault, 0);
  EXPECT_NE(sample_.status & kStatusImuFault, 0);
  EXPECT_TRUE(sample_.leg_length_m.allFinite());
}

TEST_F(BridgeTest, LinkDownAfterTimeout) {
  EXPECT_TRUE(bridge_.LinkDown(kHostEpoch));
  Deliver(0);
  EXPECT_FALSE(bridge_.LinkDown(host_now_ + 1000));
  EXPECT_TRUE(bridge_.LinkDown(host_now_ + static_cast<int64_t>(hw_.link_timeout_s * 1e6) + 1));
}

TEST_F(BridgeTest, OnlySensorFramesArePublishedOnce) {
  DecodedFrame command;
  command.type = FrameType::kCommand;
  EXPECT_EQ(bridge_.OnFrame(command, kHostEpoch, &sample_), FrameOutcome::kUnexpectedType);
  DecodedFrame sensor;
  sensor.type = FrameType::kSensor;
  sensor.sensor.seq = 4;
  sensor.sensor.adc.fill(2000);
  EXPECT_EQ(bridge_.OnFrame(sensor, kHostEpoch, &sample_), FrameOutcome::kPublish);
  EXPECT_EQ(sample_.seq, 4);
  EXPECT_EQ(bridge_.OnFrame(sensor, kHostEpoch + 10, &sample_), FrameOutcome::kDropped);
  EXPECT_EQ(bridge_.counters().reordered_frames, 1U);
}

TEST(CommandVerdict, AValidOrNonFiniteCommandGoesOutAtOnce) {
  EXPECT_TRUE(SendsAtOnce(CommandVerdict::kAccepted));
  EXPECT_TRUE(SendsAtOnce(CommandVerdict::kNonFinite));
  EXPECT_FALSE(SendsAtOnce(CommandVerdict::kOutOfOrder));
  EXPECT_FALSE(SendsAtOnce(CommandVerdict::kFuture));
}

TEST_F(BridgeTest, HealthReportsTheWorstConditionFirst) {
  LinkHealth h = bridge_.Health(kHostEpoch, "udp test");
  EXPECT_EQ(h.state, LinkState::kStarting);
  EXPECT_EQ(h.error, "no sensor frame from the device yet (udp test)");

  Deliver(0);
  Send();  // no command yet: zero drive
  h = bridge_.Health(host_now_, "udp test");
  EXPECT_EQ(h.state, LinkState::kDegraded);
  EXPECT_EQ(h.error, "zero drive: missing safe command");

  ASSERT_EQ(Command(bridge_, sample_.utime, Vector6d::Constant(10.0)), CommandVerdict::kAccepted);
  Send();
  h = bridge_.Health(host_now_, "udp test");
  EXPECT_EQ(h.state, LinkState::kOk);
  EXPECT_EQ(h.error, "");

  SensorFrame f;
  f.seq = 1;
  f.device_time_us = 1000;
  f.adc.fill(2000);
  f.status = kStatusSupplyLow;
  f.command_session = bridge_.link_session();
  ASSERT_TRUE(bridge_.OnSensorFrame(f, host_now_ + 1000, &sample_));
  h = bridge_.Health(host_now_ + 1000, "udp test");
  EXPECT_EQ(h.state, LinkState::kDegraded);
  EXPECT_EQ(h.error, "device status " + std::to_string(kStatusSupplyLow));

  h = bridge_.Health(host_now_ + 1000 + static_cast<int64_t>(hw_.link_timeout_s * 1e6) + 1, "x");
  EXPECT_EQ(h.state, LinkState::kFault);
  EXPECT_EQ(h.error, "device link down: no sensor frame for > link_timeout_s");
}

TEST_F(BridgeTest, EveryFrameCarriesTheLinkSessionDrawnAtRandom) {
  EXPECT_NE(bridge_.link_session(), 0U);
  const HwBridge other(hw_, 0.385, 0.2, 100.0);
  // Two bridges (a restart) differ: 2^32 - 1 values, drawn from the OS.
  EXPECT_NE(other.link_session(), bridge_.link_session());
  Deliver(0);
  EXPECT_EQ(Send().command.session, bridge_.link_session());
  EXPECT_EQ(Send().command.session, bridge_.link_session());
}

TEST_F(BridgeTest, ZeroDriveUntilTheDeviceFollowsTheSession) {
  // A device that still follows the bridge before this one (its session
  // 1234), then one that follows none (power-on, or rebooted).
  uint32_t k = 0;
  for (const uint32_t other : {1234U, 0U}) {
    device_session_ = other;
    Deliver(k++);
    ASSERT_EQ(Command(bridge_, sample_.utime, Vector6d::Constant(20.0)), CommandVerdict::kAccepted);
    const DecodedFrame f = Send();
    EXPECT_EQ(bridge_.last_reason(), DriveReason::kSessionPending) << other;
    for (int16_t d : f.command.drive) EXPECT_EQ(d, 0);
    EXPECT_EQ(f.command.flags & kCommandEnable, 0);
    EXPECT_EQ(bridge_.device_session(), other);
    const LinkHealth h = bridge_.Health(host_now_, "udp test");
    EXPECT_EQ(h.state, LinkState::kDegraded);
    EXPECT_NE(h.error.find("follows link session " + std::to_string(other)), std::string::npos)
        << h.error;
    Deliver(k++);  // the same device, and still not this bridge's session
  }
  EXPECT_EQ(bridge_.counters().session_pending_frames, 2U);
  EXPECT_EQ(bridge_.counters().session_pending_samples, 4U);
  // The device echoes this bridge's session: the held command goes out.
  device_session_.reset();
  Deliver(k++);
  ASSERT_EQ(Command(bridge_, sample_.utime, Vector6d::Constant(20.0)), CommandVerdict::kAccepted);
  const DecodedFrame f = Send();
  EXPECT_EQ(bridge_.last_reason(), DriveReason::kCommand);
  EXPECT_EQ(f.command.drive, DriveMap(hw_, 100.0).ForceToDrive(Vector6d::Constant(20.0)).drive);
  EXPECT_NE(f.command.flags & kCommandEnable, 0);
  // The device stops following it (rebooted: no session): zero drive at once.
  device_session_ = 0U;
  Deliver(k++);
  ASSERT_EQ(Command(bridge_, sample_.utime, Vector6d::Constant(20.0)), CommandVerdict::kAccepted);
  Send();
  EXPECT_EQ(bridge_.last_reason(), DriveReason::kSessionPending);
}

TEST_F(BridgeTest, ReportsTheDevicesSessionRejections) {
  SensorFrame f;
  f.adc.fill(2000);
  f.command_session = bridge_.link_session();
  f.rx_session_rejected = 17;
  ASSERT_TRUE(bridge_.OnSensorFrame(f, kHostEpoch, &sample_));
  EXPECT_EQ(bridge_.counters().device_rx_session_rejected, 17U);
}

TEST(DeviceClockMap, TracksDriftWithinTheBoundAndResetsOnReboot) {
  DeviceClockMap map(200.0);
  // Device clock 100 ppm slow: host advances 1.0001 ms per device ms.
  int64_t last = 0;
  for (int k = 0; k < 20000; ++k) {
    const uint64_t d = 1000ULL * static_cast<uint64_t>(k);
    const auto h = static_cast<int64_t>(1e9 + 1.0001 * static_cast<double>(d)) + 50 + (k % 7) * 30;
    const int64_t u = map.Map(d, h);
    EXPECT_LE(u, h);  // never later than the arrival
    if (k > 0) {
      EXPECT_GT(u, last);
    }
    last = u;
    if (k > 100) {
      EXPECT_GE(u, h - 50 - 6 * 30 - 5);  // follows the drift
    }
  }
  map.Map(5, 2'000'000'000);
  EXPECT_EQ(map.resets(), 1U);
}

}  // namespace
}  // namespace stewart::hw
