// The device's acceptance of command frames by link session
// (docs/wire-protocol.md, "Sessions"): CommandSessionCheck's rules one by
// one, the device (DeviceEmulator) across a bridge restart, and a bridge
// (HwBridge) and the device in a loop without transports when one bridge
// stops and another starts.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <cstdio>

#include "stewart/hw_bridge/bridge.h"
#include "stewart/hw_emulator/command_session_check.h"
#include "stewart/hw_emulator/device_emulator.h"
#include "test_config.h"

namespace stewart::hw {
namespace {

constexpr uint32_t kOld = 0xA0A0A0A0;  // the killed bridge's session
constexpr uint32_t kNew = 0x0B0B0B0B;  // the restarted bridge's

CommandFrame Frame(uint32_t session, uint32_t seq, int16_t drive) {
  CommandFrame f;
  f.session = session;
  f.seq = seq;
  f.drive.fill(drive);
  return f;
}

constexpr bool kDrives = true;     // the frame in force has not timed out
constexpr bool kTimedOut = false;  // the device's watchdog has expired

TEST(CommandSessionCheck, AtPowerOnTheFirstFrameAtRestStartsTheSession) {
  CommandSessionCheck check;
  EXPECT_EQ(check.session(), 0U);
  // A session starts at rest: a frame that asks for motion does not start one.
  EXPECT_EQ(check.Accept(Frame(kNew, 1, 3000), kTimedOut), CommandAcceptance::kNeedsNoMotion);
  EXPECT_EQ(check.session(), 0U);
  EXPECT_EQ(check.rx_session_rejected(), 1U);
  EXPECT_EQ(check.Accept(Frame(kNew, 2, 0), kTimedOut), CommandAcceptance::kAdopted);
  EXPECT_EQ(check.session(), kNew);
  EXPECT_EQ(check.Accept(Frame(kNew, 3, 3000), kDrives), CommandAcceptance::kApplied);
  EXPECT_EQ(check.rx_lost(), 0U);  // the seq check starts at the adopting frame
  // ENABLE clear is at rest too, whatever the drive field says.
  CommandSessionCheck other;
  CommandFrame off = Frame(kNew, 9, 3000);
  off.flags = 0;
  EXPECT_EQ(other.Accept(off, kTimedOut), CommandAcceptance::kAdopted);
}

TEST(CommandSessionCheck, DuplicatesAndReorderedFramesOfTheSessionAreDropped) {
  CommandSessionCheck check;
  ASSERT_EQ(check.Accept(Frame(kNew, 10, 0), kTimedOut), CommandAcceptance::kAdopted);
  EXPECT_EQ(check.Accept(Frame(kNew, 10, 500), kDrives), CommandAcceptance::kNotNewer);
  EXPECT_EQ(check.Accept(Frame(kNew, 14, 500), kDrives), CommandAcceptance::kApplied);
  EXPECT_EQ(check.rx_lost(), 3U);  // 11, 12, 13
  EXPECT_EQ(check.Accept(Frame(kNew, 12, -500), kDrives), CommandAcceptance::kNotNewer);
  EXPECT_EQ(check.Accept(Frame(kNew, 14, -500), kDrives), CommandAcceptance::kNotNewer);
  EXPECT_EQ(check.last_seq(), 14U);
  // The session's own late frames are not session rejections.
  EXPECT_EQ(check.rx_session_rejected(), 0U);
  // A frame of the session itself is accepted after its watchdog expired
  // (a bridge that stalled and goes on), not adopted anew.
  EXPECT_EQ(check.Accept(Frame(kNew, 15, 500), kTimedOut), CommandAcceptance::kApplied);
  EXPECT_EQ(check.sessions_adopted(), 1U);
}

TEST(CommandSessionCheck, TheSeqWrapsWithinASession) {
  CommandSessionCheck check;
  ASSERT_EQ(check.Accept(Frame(kNew, 0xFFFFFFFE, 0), kTimedOut), CommandAcceptance::kAdopted);
  EXPECT_EQ(check.Accept(Frame(kNew, 0xFFFFFFFF, 100), kDrives), CommandAcceptance::kApplied);
  EXPECT_EQ(check.Accept(Frame(kNew, 0, 100), kDrives), CommandAcceptance::kApplied);
  EXPECT_EQ(check.Accept(Frame(kNew, 1, 100), kDrives), CommandAcceptance::kApplied);
  EXPECT_EQ(check.rx_lost(), 0U);
  EXPECT_EQ(check.Accept(Frame(kNew, 0xFFFFFFFF, 100), kDrives), CommandAcceptance::kNotNewer);
  EXPECT_EQ(check.Accept(Frame(kNew, 3, 100), kDrives), CommandAcceptance::kApplied);
  EXPECT_EQ(check.rx_lost(), 1U);
}

TEST(CommandSessionCheck, ANewSessionOnlyOnceTheCurrentOneNoLongerDrives) {
  CommandSessionCheck check;
  ASSERT_EQ(check.Accept(Frame(kOld, 1, 0), kTimedOut), CommandAcceptance::kAdopted);
  ASSERT_EQ(check.Accept(Frame(kOld, 500000, 2000), kDrives), CommandAcceptance::kApplied);
  const uint32_t lost_before = check.rx_lost();  // 2 .. 499999 of the old session
  // A second bridge while the first one still drives: refused, counted.
  EXPECT_EQ(check.Accept(Frame(kNew, 1, 0), kDrives), CommandAcceptance::kSessionLive);
  EXPECT_EQ(check.session(), kOld);
  EXPECT_EQ(check.rx_session_rejected(), 1U);
  // The first one is gone (watchdog expired): the new session, from its seq
  // 2, lower than the old one's, is adopted at rest, and then drives.
  EXPECT_EQ(check.Accept(Frame(kNew, 2, 0), kTimedOut), CommandAcceptance::kAdopted);
  EXPECT_EQ(check.session(), kNew);
  EXPECT_EQ(check.Accept(Frame(kNew, 3, 1500), kDrives), CommandAcceptance::kApplied);
  EXPECT_EQ(check.rx_lost(), lost_before);  // no gap between two sessions' seqs
}

TEST(CommandSessionCheck, AnOldSessionsLateFrameIsNeverAppliedAgain) {
  CommandSessionCheck check;
  ASSERT_EQ(check.Accept(Frame(kOld, 1, 0), kTimedOut), CommandAcceptance::kAdopted);
  ASSERT_EQ(check.Accept(Frame(kOld, 1000, 2000), kDrives), CommandAcceptance::kApplied);
  ASSERT_EQ(check.Accept(Frame(kNew, 1, 0), kTimedOut), CommandAcceptance::kAdopted);
  // The killed bridge's frame, newer than any it sent before, arrives late.
  EXPECT_EQ(check.Accept(Frame(kOld, 1001, 2000), kDrives), CommandAcceptance::kRetiredSession);
  // Not even at rest, nor once the new session has gone quiet itself.
  EXPECT_EQ(check.Accept(Frame(kOld, 1002, 0), kTimedOut), CommandAcceptance::kRetiredSession);
  EXPECT_EQ(check.session(), kNew);
  EXPECT_EQ(check.rx_session_rejected(), 2U);
  EXPECT_EQ(check.Accept(Frame(kNew, 2, 1500), kDrives), CommandAcceptance::kApplied);
}

TEST(CommandSessionCheck, RemembersTheLastFourSessions) {
  CommandSessionCheck check;
  const std::array<uint32_t, 6> sessions = {11, 12, 13, 14, 15, 16};
  for (const uint32_t s : sessions) {
    ASSERT_EQ(check.Accept(Frame(s, 1, 0), kTimedOut), CommandAcceptance::kAdopted) << s;
  }
  // 16 is followed; 12..15 are remembered, 11 has dropped out of the memory.
  for (const uint32_t s : {12U, 13U, 14U, 15U}) {
    EXPECT_EQ(check.Accept(Frame(s, 2, 0), kTimedOut), CommandAcceptance::kRetiredSession) << s;
  }
  EXPECT_EQ(check.Accept(Frame(11, 2, 0), kTimedOut), CommandAcceptance::kAdopted);
  EXPECT_EQ(CommandSessionCheck::kRetiredSessions, 4U);
}

/// Remembers the drive; reads legs standing still mid-stroke (plausible to
/// the bridge's guard).
class StillLegsBackend : public DeviceBackend {
 public:
  void Step(const DriveArray& drive, double) override { last = drive; }
  RawReadings Sample() override {
    RawReadings r;
    r.adc.fill(2000);
    r.accel_raw = {0, 0, 8192};
    return r;
  }
  DriveArray last{};
};

// The finding: after hw_bridge was killed and restarted, the device reported
// WATCHDOG on every remaining sample, because the new bridge's seq starts
// again at 1 and the device dropped every frame as "not newer".
TEST(DeviceSession, ARestartedBridgeIsFollowedAndTheOldOnesLateFrameIsNot) {
  StillLegsBackend backend;
  DeviceEmulator device(&backend);
  constexpr uint32_t kWatchdogUs = 50000;
  uint64_t t = 1000;
  device.Tick(t);
  ASSERT_EQ(device.OnCommandFrame(Frame(kOld, 1, 0), t), CommandAcceptance::kAdopted);
  uint32_t seq = 2;
  for (; seq < 3000; ++seq) {  // the old bridge drives for 3 s
    t += 1000;
    device.Tick(t);
    ASSERT_EQ(device.OnCommandFrame(Frame(kOld, seq, 2000), t), CommandAcceptance::kApplied);
  }
  EXPECT_EQ(backend.last[0], 2000);
  // Killed: the watchdog zeroes the drive.
  t += kWatchdogUs + 1000;
  SensorFrame s = device.Tick(t);
  EXPECT_NE(s.status & kStatusWatchdog, 0);
  EXPECT_EQ(backend.last[0], 0);
  EXPECT_EQ(s.command_session, kOld);

  // The new bridge: zero drive until it sees its session echoed, then drives.
  t += 300000;
  EXPECT_EQ(device.OnCommandFrame(Frame(kNew, 1, 0), t), CommandAcceptance::kAdopted);
  s = device.Tick(t + 1000);
  EXPECT_EQ(s.status & kStatusWatchdog, 0);
  EXPECT_EQ(s.command_session, kNew);
  EXPECT_EQ(s.last_command_seq, 1U);
  EXPECT_EQ(device.OnCommandFrame(Frame(kNew, 2, 1500), t + 1000), CommandAcceptance::kApplied);
  s = device.Tick(t + 2000);
  EXPECT_EQ(backend.last[0], 1500);
  EXPECT_EQ(s.applied_drive[0], 1500);

  // A late frame of the old bridge, newer than any of its own: never applied.
  EXPECT_EQ(device.OnCommandFrame(Frame(kOld, seq, -2000), t + 2100),
            CommandAcceptance::kRetiredSession);
  s = device.Tick(t + 3000);
  EXPECT_EQ(backend.last[0], 1500);
  EXPECT_EQ(s.command_session, kNew);
  EXPECT_EQ(s.last_command_seq, 2U);
  EXPECT_EQ(s.rx_session_rejected, 1U);
}

// Two bridges and one device, without transports: the first drives, a
// second started beside it is refused while the first lives, and follows
// within a few samples once the first is gone.
TEST(DeviceSession, TheNextBridgeTakesOverOnlyOnceTheFirstIsGone) {
  const StackConfig& c = test::Config();
  const auto make_bridge = [&] {
    return HwBridge(c.hw_bridge, c.platform.leg_min_length_m,
                    c.platform.leg_max_length_m - c.platform.leg_min_length_m,
                    c.actuators.force_limit_n, {}, c.guard);
  };
  HwBridge first = make_bridge();
  HwBridge second = make_bridge();
  StillLegsBackend backend;
  DeviceEmulator device(&backend);
  constexpr int64_t kSafetySession = 9;
  constexpr int64_t kHostEpochUs = 1'000'000'000'000;
  int64_t command_seq = 0;
  // One sample at device time t_us to `bridge`: its answer (a 5 N command
  // for that sample, below the guard's force bound) goes back to the device
  // at once.
  const auto step = [&](HwBridge& bridge, uint64_t t_us, bool send) {
    const SensorFrame frame = device.Tick(t_us);
    SensorSample sample;
    if (!bridge.OnSensorFrame(frame, kHostEpochUs + static_cast<int64_t>(t_us) + 50, &sample)) {
      return frame;
    }
    if (!bridge.acceptor().has_session()) {
      bridge.OnAnnouncement({sample.utime, 1, kSafetySession}, true, 0);
    }
    ForceCommand command;
    command.utime = command.sample_utime = sample.utime;
    command.seq = ++command_seq;
    command.session_id = kSafetySession;
    command.force_n = Vector6d::Constant(5.0);
    EXPECT_EQ(bridge.OnSafeCommand(command, true), CommandVerdict::kAccepted);
    if (send) {
      std::array<uint8_t, kMaxFrameSize> buffer{};
      DecodedFrame decoded;
      const std::size_t n = bridge.BuildCommandFrame(sample.utime, buffer.data());
      EXPECT_EQ(DecodeDatagram(buffer.data(), n, &decoded), DecodeStatus::kOk);
      device.OnCommandFrame(decoded.command, t_us);
    }
    return frame;
  };
  uint64_t t = 1000;
  for (int k = 0; k < 100; ++k, t += 1000) step(first, t, true);
  EXPECT_EQ(first.last_reason(), DriveReason::kCommand);
  EXPECT_NE(backend.last[0], 0);
  // The second bridge hears the same samples and sends too: refused.
  for (int k = 0; k < 20; ++k, t += 1000) {
    step(first, t, true);
    step(second, t + 500, true);
  }
  EXPECT_EQ(second.last_reason(), DriveReason::kSessionPending);
  EXPECT_EQ(device.sessions().session(), first.link_session());
  EXPECT_GE(device.sessions().rx_session_rejected(), 20U);
  // The first bridge dies: within the watchdog and a few samples the device
  // follows the second, which then drives.
  const uint64_t died = t;
  int samples_to_drive = 0;
  while (second.last_reason() != DriveReason::kCommand && samples_to_drive < 1000) {
    step(second, t, true);
    t += 1000;
    ++samples_to_drive;
  }
  EXPECT_EQ(device.sessions().session(), second.link_session());
  const double ms = 1e-3 * static_cast<double>(t - died);
  EXPECT_LE(ms, 1e3 * c.hw_bridge.device_watchdog_s + 3.0);
  device.Tick(t);  // the physics runs under the frame just applied
  EXPECT_NE(backend.last[0], 0);
  std::printf("[device session] the second bridge drives %.0f ms after the first died\n", ms);
}

}  // namespace
}  // namespace stewart::hw
